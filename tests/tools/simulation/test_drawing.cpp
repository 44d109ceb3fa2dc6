// The object the simulated person draws on: a hole too small to draw round is closed, and only such a hole.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "engine/polygon_mesh.hpp"
#include "platform/obj.hpp"
#include "tools/simulation/simulate.hpp"

using namespace fire;
using namespace fire::simulation;

namespace {

// A flat ring of quads from radius `inner` out to 5 cm: `around` vertices on each of its two circles, the inner
// ones first. Its border is the two circles.
PolygonMesh ring(double inner, uint32_t around) {
  PolygonMesh mesh;
  for (double r : {inner, 0.05})
    for (uint32_t k = 0; k < around; ++k) {
      const double a = 2 * std::numbers::pi * k / around;
      mesh.positions.push_back(Vec3(r * std::cos(a), r * std::sin(a), 0));
    }
  for (uint32_t k = 0; k < around; ++k) {
    const uint32_t next = (k + 1) % around;
    mesh.face_vertices.insert(mesh.face_vertices.end(), {k, next, around + next, around + k});
    mesh.face_offsets.push_back(static_cast<uint32_t>(mesh.face_vertices.size()));
  }
  return mesh;
}

}  // namespace

TEST_CASE("a hole narrower than the shortest stroke closes to one vertex, the faces around it to triangles") {
  PolygonMesh mesh = ring(0.0015, 8);
  // An infinitely sharp edge out on the ring, one from the hole outward, and a corner on the outer circle.
  std::vector<uint32_t> sharp{8, 9, 0, 8};
  std::vector<uint8_t> corners(16, 0);
  corners[12] = 1;
  corners[3] = 1;
  Result<int> closed = close_small_holes(mesh, sharp, corners, kShortestStroke);
  REQUIRE(closed.ok());
  CHECK(*closed == 1);
  REQUIRE(mesh.positions.size() == 9);  // the hole's 8 vertices are one
  REQUIRE(mesh.face_count() == 8);
  for (uint32_t f = 0; f < mesh.face_count(); ++f) CHECK(mesh.face_size(f) == 3);
  const uint32_t centre = mesh.face(0)[0];
  CHECK(mesh.positions[centre].norm() < 1e-12);
  for (uint32_t f = 0; f < mesh.face_count(); ++f) CHECK(mesh.face(f)[0] == centre);
  // The outer circle is the only border left: 8 border vertices, the centre inside.
  const std::vector<uint8_t> border = border_vertices(mesh);
  CHECK(std::count(border.begin(), border.end(), 1) == 8);
  CHECK(border[centre] == 0);
  // Tags follow their vertices: the outer edge kept, the edge from the hole now from the centre; the corner on the
  // outer circle kept, the one on the hole gone with it.
  REQUIRE(sharp.size() == 4);
  CHECK((mesh.positions[sharp[0]] - Vec3(0.05, 0, 0)).norm() < 1e-12);
  CHECK(sharp[2] == centre);
  CHECK((mesh.positions[sharp[3]] - Vec3(0.05, 0, 0)).norm() < 1e-12);
  REQUIRE(corners.size() == 9);
  CHECK(std::count(corners.begin(), corners.end(), 1) == 1);
  CHECK(corners[centre] == 0);
}

TEST_CASE("a hole as wide as the shortest stroke, or wider, stays open and the mesh unchanged") {
  const PolygonMesh before = ring(0.0026, 8);  // 5.2 mm across
  PolygonMesh mesh = before;
  std::vector<uint32_t> sharp;
  std::vector<uint8_t> corners;
  Result<int> closed = close_small_holes(mesh, sharp, corners, kShortestStroke);
  REQUIRE(closed.ok());
  CHECK(*closed == 0);
  CHECK(mesh.positions == before.positions);
  CHECK(mesh.face_vertices == before.face_vertices);
}

TEST_CASE("a border through one vertex twice is refused, naming the vertex") {
  PolygonMesh mesh;
  mesh.positions = {Vec3(0, 0, 0), Vec3(0.001, 0, 0), Vec3(0, 0.001, 0), Vec3(-0.001, 0, 0), Vec3(0, -0.001, 0)};
  mesh.face_vertices = {0, 1, 2, 0, 3, 4};
  mesh.face_offsets = {0, 3, 6};
  std::vector<uint32_t> sharp;
  std::vector<uint8_t> corners;
  Result<int> closed = close_small_holes(mesh, sharp, corners, kShortestStroke);
  REQUIRE_FALSE(closed.ok());
  CHECK(closed.error() == "vertex 0 lies on the border twice");
}
