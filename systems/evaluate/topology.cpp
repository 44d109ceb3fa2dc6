// The surface's topology as `fire eval` reports it: welded vertices, then V - E + F and the border's loops.
#include <algorithm>
#include <array>
#include <map>
#include <numeric>
#include <utility>

#include "systems/evaluate/evaluate.hpp"

namespace fire::evaluate {

Topology topology(std::span<const Vec3> positions, std::span<const uint32_t> face_offsets,
                  std::span<const uint32_t> face_vertices) {
  // Coincident vertices are one: a surface written patch by patch repeats the points on patch seams.
  std::map<std::array<double, 3>, uint32_t> welded_of;
  std::vector<uint32_t> welded(positions.size());
  for (size_t i = 0; i < positions.size(); ++i)
    welded[i] = welded_of.try_emplace({positions[i].x(), positions[i].y(), positions[i].z()}, uint32_t(welded_of.size())).first->second;

  std::map<std::pair<uint32_t, uint32_t>, uint32_t> edge_uses;
  std::vector<uint8_t> used(welded_of.size(), 0);
  Topology t;
  for (size_t f = 0; f + 1 < face_offsets.size(); ++f) {
    const uint32_t begin = face_offsets[f], end = face_offsets[f + 1];
    if (end <= begin) continue;
    ++t.faces;
    for (uint32_t k = begin; k < end; ++k) {
      const uint32_t a = welded[face_vertices[k]], b = welded[face_vertices[k + 1 < end ? k + 1 : begin]];
      used[a] = 1;
      if (a != b) ++edge_uses[std::minmax(a, b)];
    }
  }
  t.vertices = size_t(std::count(used.begin(), used.end(), uint8_t{1}));
  t.edges = edge_uses.size();
  t.euler_characteristic = int64_t(t.vertices) - int64_t(t.edges) + int64_t(t.faces);

  // Border loops: the connected pieces of the edges only one face uses.
  std::vector<uint32_t> parent(welded_of.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto root = [&](uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  std::vector<uint8_t> on_border(welded_of.size(), 0);
  for (const auto& [edge, uses] : edge_uses) {
    if (uses == 1) {
      ++t.border_edges;
      on_border[edge.first] = on_border[edge.second] = 1;
      parent[root(edge.first)] = root(edge.second);
    } else if (uses > 2) {
      ++t.nonmanifold_edges;
    }
  }
  for (uint32_t v = 0; v < on_border.size(); ++v)
    if (on_border[v] && root(v) == v) ++t.border_loops;
  return t;
}

}  // namespace fire::evaluate
