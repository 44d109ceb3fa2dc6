// FIRE's Catmull-Clark on its own: exact values on a cube, stencil algebra, and rejected input.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>

#include "platform/obj.hpp"
#include "systems/catmull_clark/catmull_clark.hpp"

namespace {

namespace sd = fire::catmull_clark;
using fire::Vec3;

// Axis-aligned cube [-1, 1]^3, faces counter-clockwise seen from outside.
const std::vector<Vec3> kCubePoints = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                       {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
const std::vector<uint32_t> kCubeOffsets = {0, 4, 8, 12, 16, 20, 24};
const std::vector<uint32_t> kCubeFaces = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 2, 3, 7, 6, 1, 2, 6, 5, 3, 0, 4, 7};

sd::BaseTopology cube_topology(std::span<const uint32_t> sharp = {}) {
  return {8, kCubeOffsets, kCubeFaces, sharp};
}

std::string error_of(const sd::BaseTopology& topology, int levels = 1) {
  auto result = sd::build_refinement(topology, {levels, true});
  return result.ok() ? std::string("(accepted)") : result.error();
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("one level of a cube has the textbook Catmull-Clark points", "[subdivide]") {
  auto refinement = sd::build_refinement(cube_topology(), {1, true});
  REQUIRE(refinement.ok());
  const sd::Level& level = refinement->last();
  CHECK(level.vertex_count == 26);
  CHECK(level.face_count() == 24);
  CHECK(level.edge_count() == 48);
  std::vector<Vec3> points, scratch;
  sd::evaluate(*refinement, kCubePoints, points, scratch);
  REQUIRE(points.size() == 26);
  // Vertex points come first and keep their index: valence 3, (n-2)/n v + (sum of neighbours + sum of
  // face points) / n^2 = 5/9 of the corner.
  CHECK((points[6] - Vec3(5.0 / 9, 5.0 / 9, 5.0 / 9)).norm() < 1e-15);
  CHECK((points[0] + Vec3(5.0 / 9, 5.0 / 9, 5.0 / 9)).norm() < 1e-15);
  // Face points next (face 1 is z = +1), then edge points (edge 0 joins vertices 0 and 3).
  CHECK((points[8 + 1] - Vec3(0, 0, 1)).norm() < 1e-15);
  const auto& base = refinement->levels[0];
  REQUIRE(base.edge_vertices[0] == 0);
  REQUIRE(base.edge_vertices[1] == 3);
  CHECK((points[8 + 6 + 0] - Vec3(-0.75, 0, -0.75)).norm() < 1e-15);
  for (uint32_t v = 0; v < level.vertex_count; ++v) CHECK(level.vertex_rules[v] == sd::VertexRule::Smooth);
}

TEST_CASE("a crease keeps its edge points on the straight edge and moves along it", "[subdivide]") {
  // Sharp edges around the top face: its vertices follow the crease rule 3/4 v + 1/8 (a + b).
  const std::vector<uint32_t> sharp = {4, 5, 5, 6, 6, 7, 7, 4};
  auto refinement = sd::build_refinement(cube_topology(sharp), {1, true});
  REQUIRE(refinement.ok());
  for (uint32_t v = 4; v < 8; ++v) CHECK(refinement->levels[0].vertex_rules[v] == sd::VertexRule::Crease);
  std::vector<Vec3> points, scratch;
  sd::evaluate(*refinement, kCubePoints, points, scratch);
  CHECK((points[6] - Vec3(0.75, 0.75, 1)).norm() < 1e-15);
  for (uint32_t e = 0; e < refinement->levels[0].edge_count(); ++e) {
    if (!refinement->levels[0].edge_sharp[e]) continue;
    const auto& ev = refinement->levels[0].edge_vertices;
    CHECK((points[14 + e] - 0.5 * (kCubePoints[ev[2 * e]] + kCubePoints[ev[2 * e + 1]])).norm() < 1e-15);
  }
}

TEST_CASE("boundary edges are creases and single-face boundary vertices are corners", "[subdivide]") {
  // One quad: every vertex is a corner, every edge point the edge midpoint.
  const std::vector<Vec3> quad = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}};
  const std::vector<uint32_t> offsets = {0, 4}, faces = {0, 1, 2, 3};
  auto result = sd::subdivide({{quad, offsets, faces}, {}}, 2);
  REQUIRE(result.ok());
  for (int v = 0; v < 4; ++v) {
    CHECK((result->positions[size_t(v)] - quad[size_t(v)]).norm() == 0.0);
    CHECK((result->limit_positions[size_t(v)] - quad[size_t(v)]).norm() < 1e-15);
  }
  // A bilinear patch: every limit normal is +z, the limit surface is the square itself.
  for (size_t v = 0; v < result->limit_normals.size(); ++v) {
    CHECK((result->limit_normals[v] - Vec3(0, 0, 1)).norm() < 1e-12);
    CHECK(std::abs(result->limit_positions[v].z()) < 1e-15);
  }
  CHECK(result->quads.size() == 4 * 16);
}

TEST_CASE("given border corners: unflagged single-face boundary vertices move along their border", "[subdivide]") {
  // A 2 x 1 strip of unit quads: vertices 0 1 2 along y = 0, 3 4 5 along y = 1.
  const std::vector<Vec3> strip = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}};
  const std::vector<uint32_t> offsets = {0, 4, 8}, faces = {0, 1, 4, 3, 1, 2, 5, 4};
  const std::vector<uint8_t> only_0 = {1, 0, 0, 0, 1, 0};
  auto refinement = sd::build_refinement({6, offsets, faces, {}, only_0}, {1, true});
  REQUIRE(refinement.ok());
  const auto& rules = refinement->levels[0].vertex_rules;
  CHECK(rules[0] == sd::VertexRule::Corner);  // flagged, one face
  CHECK(rules[2] == sd::VertexRule::Crease);  // unflagged, one face: EdgeAndCorner would make it a corner
  CHECK(rules[1] == sd::VertexRule::Crease);  // unflagged, two faces: as EdgeAndCorner
  CHECK(rules[4] == sd::VertexRule::Corner);  // flagged, two faces: a corner EdgeAndCorner would not make
  // The crease rule along the border: vertex 2 moves to 3/4 of itself plus 1/8 of its border neighbours
  // (1 and 5), off its own position, where a corner would stay.
  std::vector<Vec3> points, scratch;
  sd::evaluate(*refinement, strip, points, scratch);
  CHECK((points[2] - (0.75 * strip[2] + 0.125 * (strip[1] + strip[5]))).norm() < 1e-15);
  CHECK((points[0] - strip[0]).norm() == 0.0);
  auto limit = sd::build_limit_stencils(*refinement);
  REQUIRE(limit.ok());
  // Flags for a different vertex count are refused with both counts named.
  const std::vector<uint8_t> short_flags = {1, 0};
  const std::string error = error_of({6, offsets, faces, {}, short_flags});
  CHECK(contains(error, "2 flags for 6 vertices"));
}

TEST_CASE("n-gons become n quads and the face point is their centroid", "[subdivide]") {
  // A pentagon (boundary) split into 5 quads around its centroid.
  std::vector<Vec3> pentagon;
  for (int i = 0; i < 5; ++i) pentagon.emplace_back(std::cos(0.4 * M_PI * i), std::sin(0.4 * M_PI * i), 0.0);
  const std::vector<uint32_t> offsets = {0, 5}, faces = {0, 1, 2, 3, 4};
  auto refinement = sd::build_refinement({5, offsets, faces, {}}, {1, true});
  REQUIRE(refinement.ok());
  CHECK(refinement->last().face_count() == 5);
  std::vector<Vec3> points, scratch;
  sd::evaluate(*refinement, pentagon, points, scratch);
  CHECK(points[5].norm() < 1e-15);
  // Child quad of corner 0: the corner, the next edge point, the face point, the previous edge point.
  const auto& child = refinement->last().face_vertices;
  CHECK(child[0] == 0);
  CHECK(child[1] == 5 + 1 + 0);
  CHECK(child[2] == 5);
  CHECK(child[3] == 5 + 1 + 4);
}

TEST_CASE("explicit and factorized stencil tables equal level-by-level evaluation", "[subdivide]") {
  auto mesh = fire::read_obj(std::string(FIRE_DATA_DIR) + "/meshes/rook.obj");
  REQUIRE(mesh.ok());
  // Some sharp edges, so that crease and corner rows are exercised too.
  auto base = sd::build_refinement({uint32_t(mesh->positions.size()), mesh->face_offsets, mesh->face_vertices, {}},
                                   {0, true});
  REQUIRE(base.ok());
  std::vector<uint32_t> sharp;
  const auto& edges = base->levels[0].edge_vertices;
  for (size_t e = 0; 2 * e < edges.size(); e += 4) sharp.insert(sharp.end(), {edges[2 * e], edges[2 * e + 1]});
  auto refinement = sd::build_refinement(
      {uint32_t(mesh->positions.size()), mesh->face_offsets, mesh->face_vertices, sharp}, {3, false});
  REQUIRE(refinement.ok());
  CHECK_FALSE(refinement->last().has_adjacency());

  std::vector<std::vector<Vec3>> levels;
  sd::evaluate_all_levels(*refinement, mesh->positions, levels);
  for (size_t l = 0; l < 3; ++l) {
    const sd::StencilTable table = sd::stencil_table(*refinement, l);
    REQUIRE(table.row_count() == levels[l + 1].size());
    std::vector<Vec3> rows(table.row_count());
    sd::apply(table, levels[l], rows);
    double worst = 0;
    for (size_t i = 0; i < rows.size(); ++i) worst = std::max(worst, (rows[i] - levels[l + 1][i]).norm());
    CHECK(worst < 1e-14);
  }

  const sd::StencilTable table = sd::factorize(*refinement);
  REQUIRE(table.row_count() == refinement->last().vertex_count);
  std::vector<Vec3> direct(table.row_count()), by_level, scratch;
  sd::apply(table, mesh->positions, direct);
  sd::evaluate(*refinement, mesh->positions, by_level, scratch);
  CHECK_FALSE(refinement->patches.rest.empty());  // both of evaluate's paths
  double worst = 0, worst_levels = 0;
  for (size_t i = 0; i < direct.size(); ++i) {
    worst = std::max(worst, (direct[i] - by_level[i]).norm());
    worst_levels = std::max(worst_levels, (levels.back()[i] - by_level[i]).norm());
  }
  CHECK(worst < 1e-12);
  CHECK(worst_levels < 1e-12);
  // Each row is an affine combination.
  for (uint32_t r = 0; r < table.row_count(); r += 97) {
    double sum = 0;
    for (uint32_t k = table.offsets[r]; k < table.offsets[r + 1]; ++k) sum += table.weights[k];
    CHECK(std::abs(sum - 1.0) < 1e-12);
  }
  // Without the last level's adjacency there are no limit masks.
  auto limit = sd::build_limit_stencils(*refinement);
  REQUIRE_FALSE(limit.ok());
  CHECK(contains(limit.error(), "adjacency"));
}

TEST_CASE("evaluate equals the explicit stencil rows on every shared mesh, levels 1 to 4, points moved",
          "[subdivide]") {
  // evaluate() applies the stencils through its own block-wise code; stencil_table() writes them out
  // row by row from the rules. Each level of evaluate_all_levels must equal the rows applied to the
  // level before, with and without sharp edges (creases, darts, corners), after the base points move.
  for (const char* name : {"cube", "pyramid", "torus", "pawn", "rook"}) {
    INFO(name);
    auto mesh = fire::read_obj(std::string(FIRE_DATA_DIR) + "/meshes/" + name + ".obj");
    REQUIRE(mesh.ok());
    const uint32_t n = uint32_t(mesh->positions.size());
    auto base = sd::build_refinement({n, mesh->face_offsets, mesh->face_vertices, {}}, {0, true});
    REQUIRE(base.ok());
    std::vector<uint32_t> every_third;
    const auto& edges = base->levels[0].edge_vertices;
    for (size_t e = 0; 2 * e < edges.size(); e += 3)
      every_third.insert(every_third.end(), {edges[2 * e], edges[2 * e + 1]});
    Vec3 low = mesh->positions[0], high = low;
    for (const Vec3& p : mesh->positions) {
      low = low.cwiseMin(p);
      high = high.cwiseMax(p);
    }
    const double tolerance = 1e-12 * (high - low).norm();
    for (const bool with_sharp : {true, false}) {
      const std::span<const uint32_t> sharp_edges =
          with_sharp ? std::span<const uint32_t>(every_third) : std::span<const uint32_t>();
      INFO((with_sharp ? "every third edge sharp" : "no sharp edges"));
      for (int levels = 1; levels <= 4; ++levels) {
        INFO("levels " << levels);
        auto refinement =
            sd::build_refinement({n, mesh->face_offsets, mesh->face_vertices, sharp_edges}, {levels, false});
        REQUIRE(refinement.ok());
        std::vector<Vec3> moved = mesh->positions;
        uint64_t state = 7 + uint64_t(levels);
        for (Vec3& p : moved)
          for (int axis = 0; axis < 3; ++axis) {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            p[axis] += 0.1 * (high - low).norm() * (double(state >> 11) / double(1ull << 53) - 0.5);
          }
        std::vector<std::vector<Vec3>> level_points;
        sd::evaluate_all_levels(*refinement, moved, level_points);
        std::vector<Vec3> last, scratch;
        sd::evaluate(*refinement, moved, last, scratch);
        double worst_evaluate = 0;
        for (size_t i = 0; i < last.size(); ++i)
          worst_evaluate = std::max(worst_evaluate, (last[i] - level_points.back()[i]).norm());
        CHECK(worst_evaluate <= tolerance);
        for (int l = 0; l < levels; ++l) {
          const sd::StencilTable table = sd::stencil_table(*refinement, size_t(l));
          std::vector<Vec3> rows(table.row_count());
          REQUIRE(rows.size() == level_points[size_t(l) + 1].size());
          sd::apply(table, level_points[size_t(l)], rows);
          double worst = 0;
          for (size_t i = 0; i < rows.size(); ++i)
            worst = std::max(worst, (rows[i] - level_points[size_t(l) + 1][i]).norm());
          INFO("level " << l + 1);
          CHECK(worst <= tolerance);
        }
      }
    }
  }
}

TEST_CASE("bad topology is rejected with a message naming the problem", "[subdivide]") {
  SECTION("a non-manifold edge (fan.obj)") {
    auto fan = fire::read_obj(std::string(FIRE_DATA_DIR) + "/meshes/fan.obj");
    REQUIRE(fan.ok());
    const std::string error =
        error_of({uint32_t(fan->positions.size()), fan->face_offsets, fan->face_vertices, {}});
    CHECK(contains(error, "shared by more than 2 faces"));
    CHECK(contains(error, "edge ("));
  }
  SECTION("a face with 2 vertices") {
    const std::vector<uint32_t> offsets = {0, 3, 5}, faces = {0, 1, 2, 0, 1};
    CHECK(contains(error_of({3, offsets, faces, {}}), "face 1 has fewer than 3 vertices"));
  }
  SECTION("an index out of range") {
    const std::vector<uint32_t> offsets = {0, 3}, faces = {0, 1, 7};
    CHECK(contains(error_of({3, offsets, faces, {}}), "refers to vertex 7"));
  }
  SECTION("a vertex twice in a face") {
    const std::vector<uint32_t> offsets = {0, 4}, faces = {0, 1, 0, 2};
    CHECK(contains(error_of({3, offsets, faces, {}}), "uses vertex 0 twice"));
  }
  SECTION("inconsistent orientation") {
    const std::vector<uint32_t> offsets = {0, 3, 6}, faces = {0, 1, 2, 0, 1, 3};
    CHECK(contains(error_of({4, offsets, faces, {}}), "not oriented consistently"));
  }
  SECTION("a vertex joining two fans") {
    const std::vector<uint32_t> offsets = {0, 3, 6}, faces = {0, 1, 2, 0, 3, 4};
    CHECK(contains(error_of({5, offsets, faces, {}}), "vertex 0 is not manifold"));
  }
  SECTION("a sharp edge that is not an edge") {
    const std::vector<uint32_t> sharp = {0, 6};
    CHECK(contains(error_of(cube_topology(sharp)), "sharp edge (0, 6) is not an edge"));
    const std::vector<uint32_t> odd = {0, 1, 2};
    CHECK(contains(error_of(cube_topology(odd)), "vertex pairs"));
  }
  SECTION("offsets that do not match the face vertices") {
    const std::vector<uint32_t> offsets = {0, 4}, faces = {0, 1, 2};
    CHECK(contains(error_of({3, offsets, faces, {}}), "face offsets end at 4"));
  }
  SECTION("no faces") {
    const std::vector<uint32_t> offsets = {0};
    CHECK(contains(error_of({3, offsets, {}, {}}), "no faces"));
  }
  SECTION("a level out of range or too large") {
    CHECK(contains(error_of(cube_topology(), -1), "outside 0 .. 10"));
    CHECK(contains(error_of(cube_topology(), 11), "outside 0 .. 10"));
    // 100 x 100 quads refined 10 times would have 10^4 * 4^10 faces.
    std::vector<uint32_t> offsets{0}, faces;
    for (uint32_t i = 0; i < 100; ++i)
      for (uint32_t j = 0; j < 100; ++j) {
        faces.insert(faces.end(), {i * 101 + j, i * 101 + j + 1, (i + 1) * 101 + j + 1, (i + 1) * 101 + j});
        offsets.push_back(uint32_t(faces.size()));
      }
    CHECK(contains(error_of({101 * 101, offsets, faces, {}}, 10), "more than the limit"));
  }
}

TEST_CASE("subdivide rejects non-finite points and too few levels", "[subdivide]") {
  std::vector<Vec3> points = kCubePoints;
  CHECK(contains(sd::subdivide({{points, kCubeOffsets, kCubeFaces}, {}}, 0).error(), "at least 1 level"));
  points[3].y() = std::numeric_limits<double>::quiet_NaN();
  auto result = sd::subdivide({{points, kCubeOffsets, kCubeFaces}, {}}, 1);
  REQUIRE_FALSE(result.ok());
  CHECK(contains(result.error(), "vertex 3 has a non-finite coordinate"));
}

TEST_CASE("limit masks need quads in the last level", "[subdivide]") {
  const std::vector<uint32_t> offsets = {0, 3}, faces = {0, 1, 2};
  auto refinement = sd::build_refinement({3, offsets, faces, {}}, {0, true});
  REQUIRE(refinement.ok());
  auto limit = sd::build_limit_stencils(*refinement);
  REQUIRE_FALSE(limit.ok());
  CHECK(contains(limit.error(), "face 0 of the last level has 3 vertices"));
}

TEST_CASE("a vertex without faces stays where it is", "[subdivide]") {
  std::vector<Vec3> points = kCubePoints;
  points.emplace_back(5, 5, 5);
  auto result = sd::subdivide({{points, kCubeOffsets, kCubeFaces}, {}}, 2);
  REQUIRE(result.ok());
  CHECK(result->positions[8] == Vec3(5, 5, 5));
  CHECK(result->limit_positions[8] == Vec3(5, 5, 5));
  CHECK(result->limit_normals[8] == Vec3::Zero());
}
