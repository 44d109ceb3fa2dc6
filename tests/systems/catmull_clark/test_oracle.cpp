// FIRE's Catmull-Clark against OpenSubdiv on the shared meshes: every level's topology index by index,
// every level's points, and the last level's limit positions and normals.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <string>

#include "osd_reference.hpp"
#include "platform/obj.hpp"
#include "systems/catmull_clark/catmull_clark.hpp"

namespace {

namespace sd = fire::catmull_clark;
namespace osd = fire::osd_reference;
using fire::Vec3;

const std::string kMeshDir = std::string(FIRE_DATA_DIR) + "/meshes/";

fire::PolygonMesh load(const std::string& name) {
  auto mesh = fire::read_obj(kMeshDir + name + ".obj");
  INFO(mesh.error());
  REQUIRE(mesh.ok());
  return *mesh;
}

double diagonal(const std::vector<Vec3>& points) {
  Vec3 lo = points[0], hi = points[0];
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).norm();
}

sd::BaseTopology topology_of(const fire::PolygonMesh& mesh, std::span<const uint32_t> sharp) {
  return {static_cast<uint32_t>(mesh.positions.size()), mesh.face_offsets, mesh.face_vertices, sharp};
}

sd::VertexRule rule_of(OpenSubdiv::Sdc::Crease::Rule rule) {
  using Crease = OpenSubdiv::Sdc::Crease;
  switch (rule) {
    case Crease::RULE_DART: return sd::VertexRule::Dart;
    case Crease::RULE_CREASE: return sd::VertexRule::Crease;
    case Crease::RULE_CORNER: return sd::VertexRule::Corner;
    default: return sd::VertexRule::Smooth;
  }
}

// Counts disagreements instead of asserting each one, so a failure reports the first and the count.
struct Mismatches {
  size_t count = 0;
  std::string first;
  void check(bool equal, const std::string& what) {
    if (equal) return;
    if (count++ == 0) first = what;
  }
};

void compare_topology(const sd::Level& ours, const osd::Far::TopologyLevel& theirs, int level) {
  INFO("level " << level);
  REQUIRE(ours.vertex_count == uint32_t(theirs.GetNumVertices()));
  REQUIRE(ours.face_count() == uint32_t(theirs.GetNumFaces()));
  REQUIRE(ours.edge_count() == uint32_t(theirs.GetNumEdges()));
  Mismatches m;
  for (uint32_t f = 0; f < ours.face_count(); ++f) {
    auto verts = theirs.GetFaceVertices(int(f));
    auto edges = theirs.GetFaceEdges(int(f));
    const uint32_t b = ours.face_offsets[f];
    m.check(uint32_t(verts.size()) == ours.face_offsets[f + 1] - b, "face " + std::to_string(f) + " size");
    for (int i = 0; i < verts.size(); ++i) {
      m.check(uint32_t(verts[i]) == ours.face_vertices[b + i], "face " + std::to_string(f) + " vertex");
      m.check(uint32_t(edges[i]) == ours.face_edges[b + i], "face " + std::to_string(f) + " edge");
    }
  }
  for (uint32_t e = 0; e < ours.edge_count(); ++e) {
    auto verts = theirs.GetEdgeVertices(int(e));
    auto faces = theirs.GetEdgeFaces(int(e));
    m.check(uint32_t(verts[0]) == ours.edge_vertices[2 * e] && uint32_t(verts[1]) == ours.edge_vertices[2 * e + 1],
            "edge " + std::to_string(e) + " vertices");
    const bool boundary = ours.edge_face(e, 1) == fire::kNone;
    m.check(faces.size() == (boundary ? 1 : 2), "edge " + std::to_string(e) + " face count");
    for (int i = 0; i < faces.size() && i < 2; ++i)
      m.check(uint32_t(faces[i]) == ours.edge_face(e, uint32_t(i)), "edge " + std::to_string(e) + " faces");
    const bool sharp = theirs.GetEdgeSharpness(int(e)) >= OpenSubdiv::Sdc::Crease::SHARPNESS_INFINITE;
    m.check(sharp == bool(ours.edge_sharp[e]), "edge " + std::to_string(e) + " sharpness");
  }
  for (uint32_t v = 0; v < ours.vertex_count; ++v) {
    auto edges = theirs.GetVertexEdges(int(v));
    auto faces = theirs.GetVertexFaces(int(v));
    const uint32_t r0 = ours.ring_offsets[v], n = ours.ring_offsets[v + 1] - r0;
    const std::string name = "vertex " + std::to_string(v);
    m.check(uint32_t(edges.size()) == n, name + " valence");
    uint32_t face_slot = 0;
    for (uint32_t i = 0; i < n && i < uint32_t(edges.size()); ++i) {
      m.check(uint32_t(edges[int(i)]) == ours.ring_edges[r0 + i], name + " ring edge " + std::to_string(i));
      auto ends = theirs.GetEdgeVertices(edges[int(i)]);
      m.check(uint32_t(ends[0] == int(v) ? ends[1] : ends[0]) == ours.ring_neighbors[r0 + i],
              name + " ring neighbour " + std::to_string(i));
      const uint32_t corner = ours.ring_corners[r0 + i];
      if (corner == fire::kNone) continue;
      m.check(face_slot < uint32_t(faces.size()) && uint32_t(faces[int(face_slot)]) == ours.corner_face(corner),
              name + " ring face " + std::to_string(i));
      ++face_slot;
    }
    m.check(face_slot == uint32_t(faces.size()), name + " face count");
    m.check(rule_of(theirs.GetVertexRule(int(v))) == ours.vertex_rules[v], name + " rule");
  }
  INFO("first mismatch: " << m.first);
  REQUIRE(m.count == 0);
}

double max_distance(const std::vector<Vec3>& ours, const std::vector<osd::Point>& theirs) {
  REQUIRE(ours.size() == theirs.size());
  double worst = 0;
  for (size_t i = 0; i < ours.size(); ++i) worst = std::max(worst, (ours[i] - theirs[i].vec()).norm());
  return worst;
}

// Both libraries refine `levels` times; everything is compared. The issue asks for 1e-5 of the
// diagonal; with double weights on both sides the agreement is far tighter, so 1e-9 is asserted.
// Returns whether our last level came out renumbered (evaluated from regular patches).
bool check_against_opensubdiv(const fire::PolygonMesh& mesh, std::span<const Vec3> points,
                              std::span<const uint32_t> sharp, int levels) {
  INFO("levels " << levels);
  auto ours = sd::build_refinement(topology_of(mesh, sharp), {levels, true});
  INFO(ours.error());
  REQUIRE(ours.ok());
  auto theirs = osd::refine(uint32_t(mesh.positions.size()), mesh.face_offsets, mesh.face_vertices, sharp, levels);
  for (int l = 0; l < levels; ++l) compare_topology(ours->levels[size_t(l)], theirs->GetLevel(l), l);
  // From 3 levels on, the pawn's and rook's last levels are numbered patch by patch.
  INFO((ours->last_from_osd.empty() ? "last level in OpenSubdiv's numbering" : "last level renumbered"));
  compare_topology(osd::last_level_in_osd_numbering(*ours), theirs->GetLevel(levels), levels);

  std::vector<std::vector<Vec3>> our_points;
  sd::evaluate_all_levels(*ours, points, our_points);
  our_points.back() = osd::in_osd_numbering(*ours, our_points.back());
  const auto their_points = osd::interpolate(*theirs, points);
  const double tolerance = 1e-9 * diagonal(our_points[0]);
  for (int l = 1; l <= levels; ++l) {
    INFO("points of level " << l);
    CHECK(max_distance(our_points[size_t(l)], their_points[size_t(l)]) <= tolerance);
  }
  // evaluate(): level by level, or from regular patches where the refinement has them.
  std::vector<Vec3> last, scratch;
  sd::evaluate(*ours, points, last, scratch);
  CHECK(max_distance(osd::in_osd_numbering(*ours, last), their_points.back()) <= tolerance);

  auto limit = sd::build_limit_stencils(*ours);
  INFO(limit.error());
  REQUIRE(limit.ok());
  std::vector<Vec3> positions, normals;
  sd::evaluate_limit(*limit, last, positions, normals);
  positions = osd::in_osd_numbering(*ours, positions);
  normals = osd::in_osd_numbering(*ours, normals);
  const auto their_limit = osd::limit(*theirs, their_points.back());
  CHECK(max_distance(positions, their_limit.positions) <= tolerance);
  double worst_normal = 0;
  for (size_t v = 0; v < normals.size(); ++v) {
    const Vec3 n = their_limit.tangent1[v].vec().cross(their_limit.tangent2[v].vec());
    worst_normal = std::max(worst_normal, (normals[v] - n.normalized()).norm());
  }
  CHECK(worst_normal <= 1e-9);
  return !ours->last_from_osd.empty();
}

std::vector<uint32_t> every_kth_edge(const fire::PolygonMesh& mesh, uint32_t k) {
  auto level = sd::build_refinement(topology_of(mesh, {}), {0, true});
  REQUIRE(level.ok());
  const auto& edges = level->levels[0].edge_vertices;
  std::vector<uint32_t> pairs;
  for (size_t e = 0; 2 * e < edges.size(); e += k) pairs.insert(pairs.end(), {edges[2 * e], edges[2 * e + 1]});
  return pairs;
}

}  // namespace

TEST_CASE("levels 1 to 4 equal OpenSubdiv on every manifold shared mesh", "[subdivide][opensubdiv]") {
  for (const char* name : {"cube", "pyramid", "torus", "pawn", "rook"}) {
    INFO(name);
    const auto mesh = load(name);
    for (int levels = 1; levels <= 4; ++levels) {
      const bool patches = check_against_opensubdiv(mesh, mesh.positions, {}, levels);
      // The torus is all regular patches; the pawn and rook mix them with a rest mesh; the cube and
      // pyramid have no regular quad.
      const bool has_regular_quads = std::string(name) != "cube" && std::string(name) != "pyramid";
      CHECK(patches == (levels >= 3 && has_regular_quads));
    }
  }
}

TEST_CASE("infinitely sharp creases equal OpenSubdiv", "[subdivide][opensubdiv]") {
  for (const char* name : {"cube", "torus", "pawn", "rook"}) {
    INFO(name);
    const auto mesh = load(name);
    // Every 3rd edge gives darts, interior creases and corners on the torus, pawn and rook.
    const auto sharp = every_kth_edge(mesh, 3);
    auto base = sd::build_refinement(topology_of(mesh, sharp), {0, true});
    REQUIRE(base.ok());
    if (std::string(name) != "cube") {
      const auto& rules = base->levels[0].vertex_rules;
      for (auto rule : {sd::VertexRule::Dart, sd::VertexRule::Crease, sd::VertexRule::Corner})
        CHECK(std::count(rules.begin(), rules.end(), rule) > 0);
    }
    for (int levels = 1; levels <= 3; ++levels) check_against_opensubdiv(mesh, mesh.positions, sharp, levels);
  }
}

TEST_CASE("moved base points re-evaluate through the stencils as OpenSubdiv interpolates them",
          "[subdivide][opensubdiv]") {
  const auto mesh = load("pawn");
  const int levels = 3;
  auto ours = sd::build_refinement(topology_of(mesh, {}), {levels, true});
  REQUIRE(ours.ok());
  auto theirs = osd::refine(uint32_t(mesh.positions.size()), mesh.face_offsets, mesh.face_vertices, {}, levels);
  std::vector<Vec3> moved = mesh.positions;
  std::vector<Vec3> last, scratch;
  uint64_t state = 12345;
  for (int round = 0; round < 3; ++round) {
    for (Vec3& p : moved) {
      for (int axis = 0; axis < 3; ++axis) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        p[axis] += 0.05 * (double(state >> 11) / double(1ull << 53) - 0.5);
      }
    }
    sd::evaluate(*ours, moved, last, scratch);
    const auto expected = osd::interpolate(*theirs, moved);
    CHECK(max_distance(osd::in_osd_numbering(*ours, last), expected.back()) <= 1e-9 * diagonal(moved));
  }
}
