// network_from_mesh: synthetic curve networks from the shared control meshes and hand-made ones.
#include <catch2/catch.hpp>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <string>

#include "platform/files.hpp"
#include "platform/obj.hpp"
#include "systems/catmull_clark/catmull_clark.hpp"
#include "systems/synth/network_from_mesh.hpp"

using namespace fire;

namespace {

const std::string kMeshes = std::string(FIRE_DATA_DIR) + "/meshes/";

PolygonMesh load(const std::string& name) {
  auto pm = read_obj(kMeshes + name);
  INFO(pm.error());
  REQUIRE(pm.ok());
  return *pm;
}

Result<Mesh> network(const PolygonMesh& pm, uint32_t k, double noise = 0, uint64_t seed = 0,
                     uint32_t samples = kMinSamplesPerEdge) {
  UnrefineOptions o;
  o.unrefine = k;
  o.noise_percent = noise;
  o.seed = seed;
  o.samples_per_edge = samples;
  return network_from_mesh(pm.view("test.obj"), o);
}

std::map<uint32_t, size_t> face_sizes(const Mesh& m) {
  std::map<uint32_t, size_t> sizes;
  for (FaceIndex f{0}; f < m.face_slots(); ++f)
    if (m.face_alive(f)) ++sizes[m.faces.edge_count[f]];
  return sizes;
}

bool on_border(const Mesh& m, VertexIndex v) {
  for (EdgeIndex e : m.vertex_edges(v))
    if (m.is_border_edge(e)) return true;
  return false;
}

bool on_triangle(const Mesh& m, VertexIndex v) {
  for (EdgeIndex e : m.vertex_edges(v))
    for (uint32_t f : m.edges.face[e])
      if (f != kNone && m.face_loop(FaceIndex{f}).size() == 3) return true;
  return false;
}

PolygonMesh grid(uint32_t n) {  // n x n quads in the plane z = 0, consistently oriented
  PolygonMesh pm;
  for (uint32_t y = 0; y <= n; ++y)
    for (uint32_t x = 0; x <= n; ++x) pm.positions.emplace_back(x, y, 0);
  auto id = [n](uint32_t x, uint32_t y) { return y * (n + 1) + x; };
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      for (uint32_t v : {id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1)}) pm.face_vertices.push_back(v);
      pm.face_offsets.push_back(uint32_t(pm.face_vertices.size()));
    }
  return pm;
}

double mean_control_edge_length(const PolygonMesh& pm) {
  std::map<std::pair<uint32_t, uint32_t>, double> lengths;
  for (size_t f = 0; f < pm.face_count(); ++f)
    for (uint32_t i = pm.face_offsets[f]; i < pm.face_offsets[f + 1]; ++i) {
      uint32_t a = pm.face_vertices[i], b = pm.face_vertices[i + 1 < pm.face_offsets[f + 1] ? i + 1 : pm.face_offsets[f]];
      lengths[{std::min(a, b), std::max(a, b)}] = (pm.positions[a] - pm.positions[b]).norm();
    }
  double sum = 0;
  for (auto& [key, len] : lengths) sum += len;
  return sum / double(lengths.size());
}

}  // namespace

TEST_CASE("torus: K=1 keeps every edge, K=2 every other loop", "[synth]") {
  PolygonMesh torus = load("torus.obj");
  auto k1 = network(torus, 1);
  REQUIRE(k1.ok());
  CHECK(k1->validate().empty());
  CHECK(k1->face_count() == 32);
  CHECK(k1->edge_count() == 64);
  CHECK(k1->vertex_count() == 32);
  CHECK(face_sizes(*k1) == std::map<uint32_t, size_t>{{4, 32}});

  auto k2 = network(torus, 2);
  REQUIRE(k2.ok());
  CHECK(k2->validate().empty());
  CHECK(k2->face_count() == 8);
  CHECK(k2->edge_count() == 16);
  CHECK(k2->vertex_count() == 8);
  CHECK(face_sizes(*k2) == std::map<uint32_t, size_t>{{4, 8}});
  // Every network edge of K=2 replaces two control edges: 2 * 8 + 1 points.
  for (EdgeIndex e{0}; e < k2->edge_slots(); ++e) CHECK(k2->edges.point_count[e] == 17);
}

TEST_CASE("exact counts on every shared manifold mesh for K = 1, 2, 3", "[synth]") {
  // Checked by hand: K=1 reproduces each control mesh. The cube's and the pyramid's vertices are all
  // extraordinary, so they have no loops to drop. The torus (8 x 4 loops) keeps 4 x 2, then 3 x 2 loops.
  // The pawn keeps every K-th of its 24 rings from the border and of its 24 meridians, plus the ring of
  // short loops around its valence-12 pole; border vertices of valence 2 stay (pentagons, hexagons at the
  // border). Where collapsing would leave a rook face with 2 sides (a triangle of the control mesh whose
  // third corner has valence 2), that corner stays: the face is a triangle, and its neighbour across the
  // kept corner gains a side.
  struct Expected {
    const char* mesh;
    uint32_t k;
    size_t vertices, edges, faces, points;
    std::map<uint32_t, size_t> sizes;
  };
  const std::vector<Expected> table = {
      {"cube.obj", 1, 8, 12, 6, 108, {{4, 6}}},
      {"cube.obj", 2, 8, 12, 6, 108, {{4, 6}}},
      {"cube.obj", 3, 8, 12, 6, 108, {{4, 6}}},
      {"pyramid.obj", 1, 5, 8, 5, 72, {{3, 4}, {4, 1}}},
      {"pyramid.obj", 2, 5, 8, 5, 72, {{3, 4}, {4, 1}}},
      {"pyramid.obj", 3, 5, 8, 5, 72, {{3, 4}, {4, 1}}},
      {"torus.obj", 1, 32, 64, 32, 576, {{4, 32}}},
      {"torus.obj", 2, 8, 16, 8, 272, {{4, 8}}},
      {"torus.obj", 3, 6, 12, 6, 236, {{4, 6}}},
      {"pawn.obj", 1, 601, 1188, 588, 10692, {{4, 588}}},
      {"pawn.obj", 2, 169, 324, 156, 5220, {{3, 12}, {4, 132}, {5, 12}}},
      {"pawn.obj", 3, 89, 156, 68, 3452, {{4, 60}, {6, 8}}},
      {"rook.obj", 1, 768, 1544, 777, 13896, {{3, 44}, {4, 733}}},
      {"rook.obj", 2, 320, 622, 303, 7966, {{3, 45}, {4, 209}, {5, 46}, {6, 2}, {7, 1}}},
      {"rook.obj", 3, 232, 442, 211, 6122, {{3, 49}, {4, 121}, {5, 20}, {6, 18}, {7, 3}}},
  };
  for (const Expected& x : table) {
    INFO(x.mesh << " K=" << x.k);
    auto net = network(load(x.mesh), x.k);
    INFO((net.ok() ? std::string() : net.error()));
    REQUIRE(net.ok());
    const Mesh& m = *net;
    CHECK(m.validate().empty());
    CHECK(m.vertex_count() == x.vertices);
    CHECK(m.edge_count() == x.edges);
    CHECK(m.face_count() == x.faces);
    CHECK(m.live_point_count() == x.points);
    CHECK(face_sizes(m) == x.sizes);
    // Compact: no tombstones.
    CHECK(m.vertex_slots() == x.vertices);
    CHECK(m.edge_slots() == x.edges);
    CHECK(m.face_slots() == x.faces);
    // Unrefinement keeps the topology: V - E + F of a sphere, a torus, and a disk (pawn, rook).
    const std::map<std::string, long> euler = {{"cube.obj", 2}, {"pyramid.obj", 2}, {"torus.obj", 0}, {"pawn.obj", 1}, {"rook.obj", 1}};
    CHECK(long(x.vertices) - long(x.edges) + long(x.faces) == euler.at(x.mesh));
    // Thesis figure 63: an interior vertex of valence 2 survives only as the third corner of a triangle.
    for (FaceIndex f{0}; f < m.face_slots(); ++f) CHECK(m.face_loop(f).size() >= 3);
    for (VertexIndex v{0}; v < m.vertex_slots(); ++v)
      if (!on_border(m, v) && m.valence(v) < 3) CHECK(on_triangle(m, v));
  }
}

TEST_CASE("a 4 x 4 grid unrefined by 2 keeps its border and middle lines", "[synth]") {
  // Lines 0..4 in each direction; counted from the border (0 1 2 1 0), K=2 keeps lines 0, 2, 4: four
  // regions of 2 x 2 quads. Border vertices all stay (16), plus the centre; each region has 2 + 2 border
  // edges and 2 half middle lines.
  auto net = network(grid(4), 2);
  REQUIRE(net.ok());
  const Mesh& m = *net;
  CHECK(m.validate().empty());
  CHECK(m.vertex_count() == 17);
  CHECK(m.edge_count() == 20);
  CHECK(m.face_count() == 4);
  CHECK(face_sizes(m) == std::map<uint32_t, size_t>{{6, 4}});
  size_t long_edges = 0;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e) {
    const bool border = m.is_border_edge(e);
    CHECK(m.edges.point_count[e] == (border ? 9u : 17u));
    long_edges += !border;
  }
  CHECK(long_edges == 4);
  VertexIndex centre;
  for (VertexIndex v{0}; v < m.vertex_slots(); ++v)
    if (m.vertices.position[v] == Vec3(2, 2, 0)) centre = v;
  REQUIRE(centre != kNone);
  CHECK(m.valence(centre) == 4);

  // K=3 on 3 x 3 quads keeps only the border: one 12-sided face whose every border vertex stays.
  auto coarse = network(grid(3), 3);
  REQUIRE(coarse.ok());
  CHECK(coarse->validate().empty());
  CHECK(coarse->vertex_count() == 12);
  CHECK(coarse->edge_count() == 12);
  CHECK(face_sizes(*coarse) == std::map<uint32_t, size_t>{{12, 1}});
}

TEST_CASE("a closed curve with no other vertex keeps two of its vertices", "[synth]") {
  // Two quads glued along their four edges: every vertex has valence 2, and an edge may not join a
  // vertex to itself, so two vertices stay; a third stays so that each face is a triangle, not a 2-gon.
  PolygonMesh pillow;
  pillow.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  pillow.face_vertices = {0, 1, 2, 3, 3, 2, 1, 0};
  pillow.face_offsets = {0, 4, 8};
  auto net = network(pillow, 1);
  REQUIRE(net.ok());
  CHECK(net->validate().empty());
  CHECK(net->vertex_count() == 3);
  CHECK(net->edge_count() == 3);
  CHECK(face_sizes(*net) == std::map<uint32_t, size_t>{{3, 2}});
  // The four control edges, 8 points each, in chains of 2, 1 and 1 edges: 17 + 9 + 9 points.
  std::multiset<uint32_t> counts;
  for (EdgeIndex e{0}; e < net->edge_slots(); ++e) counts.insert(net->edges.point_count[e]);
  CHECK(counts == std::multiset<uint32_t>{9, 9, 17});
}

TEST_CASE("polylines sample the control edges linearly, at least 8 points per edge", "[synth]") {
  PolygonMesh torus = load("torus.obj");
  for (uint32_t samples : {8u, 12u}) {
    auto net = network(torus, 1, 0, 0, samples);
    REQUIRE(net.ok());
    for (EdgeIndex e{0}; e < net->edge_slots(); ++e) {
      auto line = net->polyline(e);
      REQUIRE(line.size() == samples + 1);
      const Vec3 a = line.front(), b = line.back();
      for (uint32_t j = 0; j <= samples; ++j) {
        const double t = double(j) / samples;
        CHECK(line[j] == (1.0 - t) * a + t * b);
      }
    }
  }
  // At K=2 every network edge runs through a collapsed control vertex at its middle sample.
  auto net = network(torus, 2);
  REQUIRE(net.ok());
  for (EdgeIndex e{0}; e < net->edge_slots(); ++e) {
    const Vec3 middle = net->polyline(e)[8];
    CHECK(std::find(torus.positions.begin(), torus.positions.end(), middle) != torus.positions.end());
  }
  // Fewer than 8 samples per edge is refused.
  auto sparse = network(torus, 1, 0, 0, 7);
  REQUIRE_FALSE(sparse.ok());
  CHECK_THAT(sparse.error(), Catch::Contains("test.obj") && Catch::Contains("samples per edge"));
}

TEST_CASE("noise is seeded, reproducible, and moves only interior polyline points", "[synth]") {
  PolygonMesh torus = load("torus.obj");
  auto clean = network(torus, 2);
  auto a = network(torus, 2, 5.0, 42);
  auto b = network(torus, 2, 5.0, 42);
  auto c = network(torus, 2, 5.0, 43);
  REQUIRE((clean.ok() && a.ok() && b.ok() && c.ok()));
  CHECK(a->validate().empty());
  CHECK(a->same_pools(*b));
  CHECK(a->hash() == b->hash());
  CHECK_FALSE(a->same_pools(*c));
  CHECK(a->hash() != c->hash());
  CHECK_FALSE(a->same_pools(*clean));

  // Same topology and vertices; every interior point moved, ends stayed.
  REQUIRE(a->edge_slots() == clean->edge_slots());
  for (VertexIndex v{0}; v < a->vertex_slots(); ++v) CHECK(a->vertices.position[v] == clean->vertices.position[v]);
  double sum_sq = 0;
  size_t interior = 0, moved = 0;
  for (EdgeIndex e{0}; e < a->edge_slots(); ++e) {
    auto noisy = a->polyline(e), straight = clean->polyline(e);
    REQUIRE(noisy.size() == straight.size());
    CHECK(noisy.front() == straight.front());
    CHECK(noisy.back() == straight.back());
    for (size_t i = 1; i + 1 < noisy.size(); ++i) {
      ++interior;
      moved += noisy[i] != straight[i];
      sum_sq += (noisy[i] - straight[i]).squaredNorm();
    }
  }
  CHECK(moved == interior);
  // Standard deviation: 5 percent of the mean control edge length, per coordinate.
  const double sigma = 0.05 * mean_control_edge_length(torus);
  const double measured = std::sqrt(sum_sq / (3.0 * double(interior)));
  CHECK(measured == Approx(sigma).epsilon(0.1));
}

TEST_CASE("correlated noise keeps its deviation and varies smoothly along each polyline", "[synth]") {
  PolygonMesh torus = load("torus.obj");
  auto noisy = [&](double correlation) {
    UnrefineOptions o;
    o.unrefine = 2;
    o.noise_percent = 5.0;
    o.noise_correlation_percent = correlation;
    o.seed = 42;
    o.samples_per_edge = 32;
    return network_from_mesh(torus.view("torus.obj"), o);
  };
  auto clean = network(torus, 2, 0.0, 0, 32);
  auto independent = noisy(0.0), correlated = noisy(50.0);
  REQUIRE((clean.ok() && independent.ok() && correlated.ok()));
  CHECK(correlated->validate().empty());
  // No correlation is the independent model, point for point.
  CHECK(independent->same_pools(*network(torus, 2, 5.0, 42, 32)));
  // Both keep the standard deviation asked for; the correlated offsets of neighbouring points are
  // nearly equal (lag-1 correlation near 1), the independent ones unrelated (near 0).
  auto statistics = [&](const Mesh& m) {
    double squares = 0, products = 0;
    size_t count = 0, pairs = 0;
    for (EdgeIndex e{0}; e < m.edge_slots(); ++e) {
      auto line = m.polyline(e), truth = clean->polyline(e);
      for (size_t i = 1; i + 1 < line.size(); ++i) {
        const Vec3 d = line[i] - truth[i];
        squares += d.squaredNorm();
        ++count;
        if (i + 2 < line.size()) {
          products += d.dot(line[i + 1] - truth[i + 1]);
          ++pairs;
        }
      }
    }
    const double variance = squares / double(count);
    return std::pair{std::sqrt(variance / 3.0), products / double(pairs) / variance};
  };
  const double sigma = 0.05 * mean_control_edge_length(torus);
  const auto [independent_sigma, independent_lag1] = statistics(*independent);
  const auto [correlated_sigma, correlated_lag1] = statistics(*correlated);
  CHECK(independent_sigma == Approx(sigma).epsilon(0.1));
  CHECK(correlated_sigma == Approx(sigma).epsilon(0.25));
  CHECK(std::abs(independent_lag1) < 0.1);
  CHECK(correlated_lag1 > 0.9);
  UnrefineOptions bad;
  bad.noise_correlation_percent = -1;
  CHECK_THAT(network_from_mesh(torus.view("torus.obj"), bad).error(), Catch::Contains("noise correlation length"));
}

TEST_CASE("fan.obj is non-manifold: the error names an edge shared by 3 faces", "[synth]") {
  PolygonMesh fan = load("fan.obj");
  auto net = network_from_mesh(fan.view("fan.obj"), UnrefineOptions{});
  REQUIRE_FALSE(net.ok());
  CHECK(net.error() ==
        "fan.obj: edge between vertices 8 and 9 (OBJ numbering) is shared by 3 faces; a polyline mesh needs a manifold mesh");
}

TEST_CASE("faces walking an edge the same way are rejected", "[synth]") {
  PolygonMesh flipped;
  flipped.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  flipped.face_vertices = {0, 1, 2, 2, 0, 3};  // both faces walk vertex 3 -> vertex 1
  flipped.face_offsets = {0, 3, 6};
  auto net = network(flipped, 1);
  REQUIRE_FALSE(net.ok());
  CHECK_THAT(net.error(), Catch::Contains("test.obj: faces 1 and 2") && Catch::Contains("oriented consistently"));
}

TEST_CASE("an unrefinement too coarse for the mesh is refused with the reason", "[synth]") {
  // The torus has 4 loops around its tube: K=4 keeps one, which cannot bound disks.
  PolygonMesh torus = load("torus.obj");
  auto net = network_from_mesh(torus.view("torus.obj"), UnrefineOptions{4});
  REQUIRE_FALSE(net.ok());
  CHECK_THAT(net.error(), Catch::StartsWith("unrefine 4 too coarse for torus.obj: the region merged from") &&
                              Catch::Contains("is not a disk"));
}

TEST_CASE("bad OBJ input is reported with the file and the problem", "[synth]") {
  auto text = [](const char* s) { return std::string(s); };
  SECTION("truncated in a vertex line") {
    auto pm = parse_obj(text("v 0 0 0\nv 1 0 0\nv 1 1"), "cut.obj");
    REQUIRE_FALSE(pm.ok());
    CHECK_THAT(pm.error(), Catch::StartsWith("cut.obj:3:") && Catch::Contains("three coordinates"));
  }
  SECTION("truncated before the faces") {
    auto pm = parse_obj(text("v 0 0 0\nv 1 0 0\nv 1 1 0\n"), "nofaces.obj");
    REQUIRE_FALSE(pm.ok());
    CHECK_THAT(pm.error(), Catch::StartsWith("nofaces.obj") && Catch::Contains("no faces"));
  }
  SECTION("malformed face") {
    auto pm = parse_obj(text("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 x\n"), "bad.obj");
    REQUIRE_FALSE(pm.ok());
    CHECK_THAT(pm.error(), Catch::StartsWith("bad.obj:4:"));
  }
  SECTION("NaN coordinate") {
    auto pm = parse_obj(text("v 0 0 0\nv nan 0 0\nv 1 1 0\nf 1 2 3\n"), "nan.obj");
    REQUIRE_FALSE(pm.ok());
    CHECK_THAT(pm.error(), Catch::StartsWith("nan.obj:2:") && Catch::Contains("not finite"));
  }
  SECTION("empty file") {
    auto pm = parse_obj(text(""), "empty.obj");
    REQUIRE_FALSE(pm.ok());
    CHECK_THAT(pm.error(), Catch::StartsWith("empty.obj") && Catch::Contains("no vertices"));
  }
  SECTION("missing file") {
    auto pm = read_obj(kMeshes + "no-such-mesh.obj");
    REQUIRE_FALSE(pm.ok());
    CHECK_THAT(pm.error(), Catch::Contains("no-such-mesh.obj"));
  }
}

TEST_CASE("bad views and options are refused, naming the source", "[synth]") {
  PolygonMesh quad;
  quad.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  quad.face_vertices = {0, 1, 2, 3};
  quad.face_offsets = {0, 4};
  REQUIRE(network(quad, 1).ok());
  CHECK(network(quad, 1)->face_count() == 1);

  CHECK_THAT(network(quad, 0).error(), Catch::Contains("unrefine must be at least 1"));
  CHECK_THAT(network(quad, 1, -1.0).error(), Catch::Contains("noise percent"));
  CHECK_THAT(network(quad, 1, std::nan("")).error(), Catch::Contains("noise percent"));
  PolygonMesh huge = quad;
  for (Vec3& p : huge.positions) p *= 1e300;
  CHECK_THAT(network(huge, 1, 1e10).error(), Catch::Contains("overflows"));

  PolygonMesh nan = quad;
  nan.positions[2] = Vec3(1, std::nan(""), 0);
  CHECK(network(nan, 1).error() == "test.obj: vertex 3 has a non-finite coordinate");
  PolygonMesh out_of_range = quad;
  out_of_range.face_vertices[3] = 9;
  CHECK(network(out_of_range, 1).error() == "test.obj: face 1 uses vertex 10 that does not exist");
  PolygonMesh repeated = quad;
  repeated.face_vertices[3] = 1;
  CHECK(network(repeated, 1).error() == "test.obj: face 1 uses vertex 2 twice");
  PolygonMesh faceless = quad;
  faceless.face_vertices.clear();
  faceless.face_offsets = {0};
  CHECK_THAT(network(faceless, 1).error(), Catch::Contains("no faces"));
}

TEST_CASE("limit sampling: every polyline point lies on the control mesh's Catmull-Clark limit surface", "[synth][limit]") {
  for (const char* name : {"torus.obj", "pawn.obj", "rook.obj"}) {
    INFO(name);
    PolygonMesh pm = load(name);
    UnrefineOptions o;
    o.unrefine = 2;
    o.limit = true;
    auto net = network_from_mesh(pm.view(name), o);
    REQUIRE(net.ok());
    REQUIRE(net->validate() == "");
    // The same topology as the linear network, only the points move.
    auto linear = network(pm, 2);
    REQUIRE(linear.ok());
    CHECK(net->face_count() == linear->face_count());
    CHECK(net->edge_count() == linear->edge_count());
    CHECK(net->live_point_count() == linear->live_point_count());
    // Ground truth straight from the subdivision library: limit positions of the level-3 vertices.
    auto truth = catmull_clark::subdivide({pm.view(), {}}, 3);
    REQUIRE(truth.ok());
    std::vector<std::array<double, 3>> on_surface;
    for (const Vec3& p : truth->limit_positions) on_surface.push_back({p.x(), p.y(), p.z()});
    std::sort(on_surface.begin(), on_surface.end());
    size_t found = 0, total = 0;
    for (EdgeIndex e{0}; e < net->edge_slots(); ++e)
      for (const Vec3& p : net->polyline(e)) {
        ++total;
        found += std::binary_search(on_surface.begin(), on_surface.end(), std::array<double, 3>{p.x(), p.y(), p.z()});
      }
    CHECK(found == total);
    // Network vertices are the control vertices' limit positions.
    for (VertexIndex v{0}; v < net->vertex_slots(); ++v) {
      const Vec3& p = net->vertices.position[v];
      CHECK(std::binary_search(on_surface.begin(), on_surface.end(), std::array<double, 3>{p.x(), p.y(), p.z()}));
    }
  }
}

TEST_CASE("creases: kept whatever K, marked sharp, and the limit curves along them are the box's straight edges", "[synth][limit][crease]") {
  const std::string path = kMeshes + "box.obj";
  auto text = read_text_file(path);
  REQUIRE(text.ok());
  auto pm = parse_obj(*text, path);
  REQUIRE(pm.ok());
  auto tags = parse_obj_tags(*text, path, *pm);
  REQUIRE(tags.ok());
  REQUIRE(tags->sharp_edges.size() == 2 * 48);  // 12 edges of the box, 4 control edges each
  Vec3 lo = pm->positions[0], hi = lo;
  for (const Vec3& p : pm->positions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  // On a box's edge: two of the three coordinates at the box's extremes.
  auto on_box_edge = [&](const Vec3& p) {
    int at_side = 0;
    for (int i = 0; i < 3; ++i) at_side += std::abs(p[i] - lo[i]) < 1e-9 || std::abs(p[i] - hi[i]) < 1e-9;
    return at_side >= 2;
  };
  UnrefineOptions o{.unrefine = 2, .limit = true, .sharp_edges = tags->sharp_edges};
  auto net = network_from_mesh(pm->view("box.obj"), o);
  REQUIRE(net.ok());
  REQUIRE(net->validate() == "");
  // Every other grid line of each side, counted from the creases: 2 x 2 faces a side, each edge of the box two curves.
  CHECK(net->face_count() == 24);
  CHECK(net->edge_count() == 48);
  size_t sharp = 0;
  for (EdgeIndex e{0}; e < net->edge_slots(); ++e) {
    if (!(net->edges.flags[e] & kSharpEdge)) continue;
    ++sharp;
    for (const Vec3& p : net->polyline(e)) {
      INFO("edge " << e << " point " << p.transpose());
      CHECK(on_box_edge(p));
    }
  }
  CHECK(sharp == 24);
  // Without the tags, K = 2 counts its loops from another line and drops the box's edges: the limit is round there.
  auto smooth = network_from_mesh(pm->view("box.obj"), UnrefineOptions{.unrefine = 2, .limit = true});
  REQUIRE(smooth.ok());
  for (EdgeIndex e{0}; e < smooth->edge_slots(); ++e) CHECK_FALSE(smooth->edges.flags[e] & kSharpEdge);
  size_t on_edges = 0;
  for (VertexIndex v{0}; v < smooth->vertex_slots(); ++v) on_edges += on_box_edge(smooth->vertices.position[v]);
  CHECK(on_edges == 0);
}
