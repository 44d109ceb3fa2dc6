#pragma once
// OpenSubdiv as the oracle: the same mesh refined by Far::TopologyRefiner with the options FIRE's
// subdivision claims to match (Catmark, VTX_BOUNDARY_EDGE_AND_CORNER, infinitely sharp creases).
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <memory>
#include <span>
#include <vector>

#include "engine/common.hpp"
#include "systems/catmull_clark/catmull_clark.hpp"

namespace fire::osd_reference {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

// Vertex data in the form Far's templates expect.
struct Point {
  double xyz[3];
  void Clear(void* = nullptr) { xyz[0] = xyz[1] = xyz[2] = 0.0; }
  void AddWithWeight(const Point& src, double weight) {
    xyz[0] += weight * src.xyz[0];
    xyz[1] += weight * src.xyz[1];
    xyz[2] += weight * src.xyz[2];
  }
  Vec3 vec() const { return {xyz[0], xyz[1], xyz[2]}; }
};

inline std::vector<Point> to_points(std::span<const Vec3> positions) {
  std::vector<Point> points(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) points[i] = {{positions[i].x(), positions[i].y(), positions[i].z()}};
  return points;
}

inline Sdc::Options catmark_options() {
  Sdc::Options options;
  options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
  return options;
}

// Catmark with our options, refined uniformly to `levels`; the full topology in the last level is what
// Limit needs (OpenSubdiv's default builds only the last level's faces).
inline std::unique_ptr<Far::TopologyRefiner> refine_uniform(const Far::TopologyDescriptor& descriptor, int levels,
                                                            bool full_last_level) {
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  std::unique_ptr<Far::TopologyRefiner> refiner(
      Factory::Create(descriptor, Factory::Options(Sdc::SCHEME_CATMARK, catmark_options())));
  Far::TopologyRefiner::UniformOptions uniform(levels);
  uniform.fullTopologyInLastLevel = full_last_level;
  refiner->RefineUniform(uniform);
  return refiner;
}

// Refined uniformly to `levels` with the full topology in the last level (needed for Limit).
inline std::unique_ptr<Far::TopologyRefiner> refine(uint32_t vertex_count, std::span<const uint32_t> face_offsets,
                                                    std::span<const uint32_t> face_vertices,
                                                    std::span<const uint32_t> sharp_edges, int levels) {
  std::vector<int> sizes(face_offsets.size() - 1);
  for (size_t f = 0; f + 1 < face_offsets.size(); ++f) sizes[f] = int(face_offsets[f + 1] - face_offsets[f]);
  std::vector<Far::Index> indices(face_vertices.begin(), face_vertices.end());
  std::vector<Far::Index> crease_pairs(sharp_edges.begin(), sharp_edges.end());
  std::vector<float> crease_weights(sharp_edges.size() / 2, Sdc::Crease::SHARPNESS_INFINITE);

  Far::TopologyDescriptor descriptor;
  descriptor.numVertices = int(vertex_count);
  descriptor.numFaces = int(sizes.size());
  descriptor.numVertsPerFace = sizes.data();
  descriptor.vertIndicesPerFace = indices.data();
  descriptor.numCreases = int(crease_weights.size());
  descriptor.creaseVertexIndexPairs = crease_pairs.data();
  descriptor.creaseWeights = crease_weights.data();
  return refine_uniform(descriptor, levels, true);
}

// Points of every level, interpolated with double weights.
inline std::vector<std::vector<Point>> interpolate(const Far::TopologyRefiner& refiner, std::span<const Vec3> base) {
  std::vector<std::vector<Point>> levels(refiner.GetMaxLevel() + 1);
  levels[0] = to_points(base);
  Far::PrimvarRefinerReal<double> primvar(refiner);
  for (int l = 1; l <= refiner.GetMaxLevel(); ++l) {
    levels[l].resize(refiner.GetLevel(l).GetNumVertices());
    const Point* src = levels[l - 1].data();
    Point* dst = levels[l].data();  // Far takes the destination by non-const reference
    primvar.Interpolate(l, src, dst);
  }
  return levels;
}

struct Limit {
  std::vector<Point> positions, tangent1, tangent2;
};
inline Limit limit(const Far::TopologyRefiner& refiner, const std::vector<Point>& last_level) {
  Limit result;
  const size_t n = last_level.size();
  result.positions.resize(n);
  result.tangent1.resize(n);
  result.tangent2.resize(n);
  const Point* src = last_level.data();
  Point* positions = result.positions.data();
  Point* tangent1 = result.tangent1.data();
  Point* tangent2 = result.tangent2.data();
  Far::PrimvarRefinerReal<double>(refiner).Limit(src, positions, tangent1, tangent2);
  return result;
}

// Per-vertex values of our last level (points, limit positions, normals) in OpenSubdiv's numbering.
inline std::vector<Vec3> in_osd_numbering(const catmull_clark::Refinement& refinement, const std::vector<Vec3>& values) {
  if (refinement.last_from_osd.empty()) return values;
  std::vector<Vec3> out(values.size());
  for (size_t v = 0; v < values.size(); ++v) out[v] = values[refinement.last_from_osd[v]];
  return out;
}

// Our last level with OpenSubdiv's vertex numbering (faces and edges keep theirs).
inline catmull_clark::Level last_level_in_osd_numbering(const catmull_clark::Refinement& refinement) {
  catmull_clark::Level level = refinement.last();
  const std::vector<uint32_t>& ours = refinement.last_from_osd;
  if (ours.empty()) return level;
  std::vector<uint32_t> theirs(ours.size());
  for (uint32_t v = 0; v < ours.size(); ++v) theirs[ours[v]] = v;
  for (uint32_t& v : level.face_vertices) v = theirs[v];
  for (uint32_t& v : level.edge_vertices) v = theirs[v];
  if (!level.has_adjacency()) return level;
  const catmull_clark::Level& last = refinement.last();
  level.ring_offsets.assign(1, 0);
  level.ring_edges.clear();
  level.ring_neighbors.clear();
  level.ring_corners.clear();
  for (uint32_t v = 0; v < ours.size(); ++v) {
    const uint32_t w = ours[v];
    for (uint32_t r = last.ring_offsets[w]; r < last.ring_offsets[w + 1]; ++r) {
      level.ring_edges.push_back(last.ring_edges[r]);
      level.ring_neighbors.push_back(theirs[last.ring_neighbors[r]]);
      level.ring_corners.push_back(last.ring_corners[r]);
    }
    level.ring_offsets.push_back(static_cast<uint32_t>(level.ring_edges.size()));
    level.vertex_rules[v] = last.vertex_rules[w];
  }
  return level;
}

}  // namespace fire::osd_reference
