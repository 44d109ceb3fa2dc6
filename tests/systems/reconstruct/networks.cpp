#include "networks.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <numbers>

#include "systems/catmull_clark/catmull_clark.hpp"

namespace fire::test {

namespace {

// Builds faces from loops of (edge, reversed) and checks the result.
void add_face(Mesh& m, std::initializer_list<std::pair<uint32_t, bool>> loop) {
  std::vector<OrientedEdge> oriented;
  for (auto [e, reversed] : loop) oriented.push_back(make_oriented(EdgeIndex{e}, reversed));
  REQUIRE(m.add_face(oriented) != kNone);
}

// Corner k of n evenly spaced round the unit circle: angle 2 pi k / n.
std::vector<double> even_angles(uint32_t n) {
  std::vector<double> angles;
  for (uint32_t k = 0; k < n; ++k) angles.push_back(2 * std::numbers::pi * k / n);
  return angles;
}

}  // namespace

Mesh polygon_network(uint32_t n, uint32_t samples) { return polygon_network(even_angles(n), samples); }

Mesh polygon_network(const std::vector<double>& angles, uint32_t samples) {
  Mesh m;
  auto point = [](double angle) { return Vec3(std::cos(angle), std::sin(angle), 0.2 * std::cos(2 * angle)); };
  const size_t n = angles.size();
  std::vector<VertexIndex> corners;
  for (double a : angles) corners.push_back(m.add_vertex(point(a)));
  std::vector<OrientedEdge> oriented;
  for (size_t k = 0; k < n; ++k) {
    const double from = angles[k], to = k + 1 < n ? angles[k + 1] : angles[0] + 2 * std::numbers::pi;
    std::vector<Vec3> line;
    for (uint32_t i = 0; i < samples; ++i) line.push_back(point(from + (to - from) * i / (samples - 1)));
    oriented.push_back(make_oriented(m.add_edge(corners[k], corners[(k + 1) % n], line), false));
  }
  REQUIRE(m.add_face(oriented) != kNone);
  REQUIRE(m.validate() == "");
  return m;
}

Mesh cornered_polygon_network(uint32_t n, uint32_t samples) { return cornered_polygon_network(even_angles(n), samples); }

Mesh cornered_polygon_network(const std::vector<double>& angles, uint32_t samples) {
  Mesh m;
  auto lifted = [](const Eigen::Vector2d& q) { return Vec3(q.x(), q.y(), 0.2 * std::cos(2 * std::atan2(q.y(), q.x()))); };
  const size_t n = angles.size();
  std::vector<Eigen::Vector2d> at;
  std::vector<VertexIndex> corners;
  for (double a : angles) {
    at.emplace_back(std::cos(a), std::sin(a));
    corners.push_back(m.add_vertex(lifted(at.back())));
  }
  std::vector<OrientedEdge> oriented;
  for (size_t k = 0; k < n; ++k) {
    const Eigen::Vector2d &from = at[k], &to = at[(k + 1) % n];
    std::vector<Vec3> line;
    for (uint32_t i = 0; i < samples; ++i) line.push_back(lifted(from + (to - from) * (double(i) / (samples - 1))));
    oriented.push_back(make_oriented(m.add_edge(corners[k], corners[(k + 1) % n], line), false));
  }
  REQUIRE(m.add_face(oriented) != kNone);
  REQUIRE(m.validate() == "");
  return m;
}

Mesh grid_network(uint32_t nx, uint32_t ny, uint32_t samples, const Height& height) {
  Mesh m;
  auto at = [&](double x, double y) { return Vec3(x, y, height(x, y)); };
  std::vector<VertexIndex> v((nx + 1) * (ny + 1));
  for (uint32_t j = 0; j <= ny; ++j)
    for (uint32_t i = 0; i <= nx; ++i) v[j * (nx + 1) + i] = m.add_vertex(at(i, j));
  auto curve = [&](double x0, double y0, double x1, double y1) {
    std::vector<Vec3> line;
    for (uint32_t s = 0; s < samples; ++s) {
      const double w = double(s) / (samples - 1);
      line.push_back(at(x0 + (x1 - x0) * w, y0 + (y1 - y0) * w));
    }
    return line;
  };
  for (uint32_t j = 0; j <= ny; ++j)
    for (uint32_t i = 0; i < nx; ++i) m.add_edge(v[j * (nx + 1) + i], v[j * (nx + 1) + i + 1], curve(i, j, i + 1, j));
  const uint32_t vertical = (ny + 1) * nx;
  for (uint32_t j = 0; j < ny; ++j)
    for (uint32_t i = 0; i <= nx; ++i) m.add_edge(v[j * (nx + 1) + i], v[(j + 1) * (nx + 1) + i], curve(i, j, i, j + 1));
  for (uint32_t j = 0; j < ny; ++j)
    for (uint32_t i = 0; i < nx; ++i)
      add_face(m, {{j * nx + i, false},
                   {vertical + j * (nx + 1) + i + 1, false},
                   {(j + 1) * nx + i, true},
                   {vertical + j * (nx + 1) + i, true}});
  REQUIRE(m.validate() == "");
  return m;
}

Mesh limit_grid_network(uint32_t m, uint32_t levels, const Height& height) {
  const uint32_t cells = 2 * m, side = cells + 1;
  std::vector<Vec3> flat, lifted;
  for (uint32_t j = 0; j < side; ++j)
    for (uint32_t i = 0; i < side; ++i) {
      flat.emplace_back(i, j, 0);
      lifted.emplace_back(i, j, height(i, j));
    }
  std::vector<uint32_t> offsets{0}, quads;
  for (uint32_t j = 0; j < cells; ++j)
    for (uint32_t i = 0; i < cells; ++i) {
      quads.insert(quads.end(), {j * side + i, j * side + i + 1, (j + 1) * side + i + 1, (j + 1) * side + i});
      offsets.push_back(static_cast<uint32_t>(quads.size()));
    }
  auto limit_of = [&](const std::vector<Vec3>& points) {
    auto s = catmull_clark::subdivide({{points, offsets, quads}, {}}, static_cast<int>(levels));
    REQUIRE(s.ok());
    return s->limit_positions;
  };
  // Catmull-Clark reproduces the flat grid's linear coordinates, so the flat twin's limit points name
  // each limit vertex's (u, v) on the grid exactly (multiples of 2^-levels).
  const std::vector<Vec3> uv = limit_of(flat), surface = limit_of(lifted);
  const double steps = double(1u << levels);
  std::map<std::pair<long, long>, Vec3> on_grid;
  for (size_t k = 0; k < uv.size(); ++k)
    on_grid[{std::lround(uv[k].x() * steps), std::lround(uv[k].y() * steps)}] = surface[k];

  Mesh net;
  const uint32_t per_edge = 2u << levels;  // samples along two control edges
  auto sample = [&](uint32_t i, uint32_t j, uint32_t di, uint32_t dj) {
    std::vector<Vec3> line;
    for (uint32_t s = 0; s <= per_edge; ++s) {
      auto it = on_grid.find({long(i * steps + di * s), long(j * steps + dj * s)});
      REQUIRE(it != on_grid.end());
      line.push_back(it->second);
    }
    return line;
  };
  std::vector<VertexIndex> v((m + 1) * (m + 1));
  for (uint32_t j = 0; j <= m; ++j)
    for (uint32_t i = 0; i <= m; ++i) v[j * (m + 1) + i] = net.add_vertex(on_grid.at({long(2 * i * steps), long(2 * j * steps)}));
  for (uint32_t j = 0; j <= m; ++j)
    for (uint32_t i = 0; i < m; ++i) net.add_edge(v[j * (m + 1) + i], v[j * (m + 1) + i + 1], sample(2 * i, 2 * j, 1, 0));
  const uint32_t vertical = (m + 1) * m;
  for (uint32_t j = 0; j < m; ++j)
    for (uint32_t i = 0; i <= m; ++i) net.add_edge(v[j * (m + 1) + i], v[(j + 1) * (m + 1) + i], sample(2 * i, 2 * j, 0, 1));
  for (uint32_t j = 0; j < m; ++j)
    for (uint32_t i = 0; i < m; ++i)
      add_face(net, {{j * m + i, false},
                     {vertical + j * (m + 1) + i + 1, false},
                     {(j + 1) * m + i, true},
                     {vertical + j * (m + 1) + i, true}});
  REQUIRE(net.validate() == "");
  return net;
}

}  // namespace fire::test
