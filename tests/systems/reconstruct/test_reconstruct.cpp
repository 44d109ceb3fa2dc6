// The two pipelines on tiny hand-made networks: exact counts, the Coons centre, the FIRE fit passing
// through the drawn samples, and rejected input.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "networks.hpp"
#include "systems/reconstruct/fit.hpp"
#include "systems/reconstruct/reconstruct.hpp"

using namespace fire;
using namespace fire::reconstruct;
using namespace fire::test;

namespace {

FacePatch patch_of(const Mesh& net, FaceIndex face, const FaceSettings& settings, std::vector<EdgeSplits>& splits) {
  splits.clear();
  for (OrientedEdge oe : net.face_loop(face)) splits.push_back(split_network_edge(net.polyline(edge_of(oe)), settings.coons_steps));
  std::vector<const EdgeSplits*> pointers;
  for (const EdgeSplits& s : splits) pointers.push_back(&s);
  return build_face_patch(net, face, pointers, settings);
}

BaseMesh base_of(const Mesh& net, const Options& options) {
  ReconstructionState state;
  SurfaceMesh surface;
  Status s = reconstruct_update(net, options, state, surface);
  INFO(s.error);
  REQUIRE(s.ok());
  return state.base();
}

// Every base edge carries exactly one curve and the base mesh is a disk: V - E + F = 1.
void check_disk(const BaseMesh& b) {
  CHECK(int64_t(b.vertex_count()) - int64_t(b.curve_count()) + int64_t(b.face_count()) == 1);
  for (uint32_t f = 0; f < b.face_count(); ++f) CHECK(b.face_offsets[f + 1] - b.face_offsets[f] == 4);
}

double nearest_distance(const std::vector<Vec3>& points, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& q : points) best = std::min(best, (q - p).norm());
  return best;
}

}  // namespace

TEST_CASE("thesis: a pentagon triquadrifies into a quad and a triangle, then 7 quads", "[reconstruct][thesis]") {
  const Mesh net = polygon_network(5);
  std::vector<EdgeSplits> splits;
  const FacePatch p = patch_of(net, FaceIndex{0}, {Method::Thesis, 1, Planarity::LeastSquares}, splits);
  CHECK(p.first_stage_sizes == std::vector<uint32_t>{4, 3});
  CHECK(p.face_count() == 7);
  CHECK(p.interior.size() == 3);  // the cut's midpoint and the two centres
  const BaseMesh b = base_of(net, {Method::Thesis, 1, 2, Planarity::LeastSquares});
  CHECK(b.vertex_count() == 13);  // 5 corners, 5 edge midpoints, 3 inside
  CHECK(b.face_count() == 7);
  CHECK(b.curve_count() == 19);   // 10 halves of the sides, 2 of the cut, 4 + 3 spokes
  check_disk(b);
  // The cut is straight (thesis) and sampled like the sides: its two halves are the only inner curves
  // with more than 2 points (one Coons step makes spokes of 2 points), and they lie on one line.
  std::vector<uint32_t> sampled;
  for (uint32_t c = 0; c < b.curve_count(); ++c)
    if (!b.curve_drawn[c] && b.curve(c).size() > 2) sampled.push_back(c);
  REQUIRE(sampled.size() == 2);
  const Vec3 from = b.curve(sampled[0]).front(), d = (b.curve(sampled[0]).back() - from).normalized();
  for (uint32_t c : sampled) {
    for (const Vec3& q : b.curve(c)) CHECK(((q - from) - d * d.dot(q - from)).norm() < 1e-12);
  }
}

TEST_CASE("thesis: the centre of a 4-sided face is its Coons point x(1/2, 1/2)", "[reconstruct][thesis]") {
  const Mesh net = polygon_network(4, 11);
  std::vector<EdgeSplits> splits;
  const FacePatch p = patch_of(net, FaceIndex{0}, {Method::Thesis, 1, Planarity::LeastSquares}, splits);
  REQUIRE(p.interior.size() == 1);
  std::vector<std::vector<double>> params;
  std::vector<Side> sides;
  for (OrientedEdge oe : net.face_loop(FaceIndex{0})) params.push_back(arc_parameters(net.polyline(edge_of(oe))));
  for (uint32_t k = 0; k < 4; ++k) sides.push_back({net.polyline(edge_of(net.face_loop(FaceIndex{0})[k])), params[k], false});
  CHECK(p.interior[0] == coons_point(sides, 0.5, 0.5, Sampling::Nearest));
  // Two steps: a 5 x 5 grid of base vertices.
  const BaseMesh b = base_of(net, {Method::Thesis, 2, 1, Planarity::LeastSquares});
  CHECK(b.vertex_count() == 25);
  CHECK(b.face_count() == 16);
  check_disk(b);
}

TEST_CASE("FIRE: the last Coons step's spokes are their two ends, an earlier step's are sampled for the next",
          "[reconstruct][fire]") {
  // A fine polygon (129 points a side), whose spokes would otherwise be sampled as densely as its sides.
  const Mesh net = cornered_polygon_network(7, 129);
  for (uint32_t steps : {1u, 2u}) {
    const BaseMesh b = base_of(net, {Method::Fire, steps, 2, Planarity::LeastSquares});
    INFO(steps << " Coons steps");
    size_t longest = 0, undrawn = 0;
    for (uint32_t c = 0; c < b.curve_count(); ++c) {
      if (b.curve_drawn[c]) continue;
      ++undrawn;
      longest = std::max(longest, b.curve(c).size());
    }
    REQUIRE(undrawn > 0);
    // One step: 7 spokes of 2 points. Two: the first step's spokes were sampled densely and are split in
    // halves by the second, whose own spokes are 2 points again.
    if (steps == 1) CHECK(longest == 2);
    else CHECK(longest > 4);
  }
}

TEST_CASE("FIRE: an n-sided face becomes n quads around its centre", "[reconstruct][fire]") {
  for (uint32_t n : {2u, 3u, 4u, 5u, 6u}) {
    const Mesh net = n == 2 ? polygon_network(n) : cornered_polygon_network(n);
    const BaseMesh b = base_of(net, {Method::Fire, 1, 2, Planarity::LeastSquares});
    INFO("n = " << n);
    CHECK(b.vertex_count() == 2 * n + 1);
    CHECK(b.face_count() == n);
    CHECK(b.curve_count() == 3 * n);
    check_disk(b);
    const uint32_t centre = 2 * n;  // corners, then edge midpoints, then the face's vertex
    for (uint32_t f = 0; f < n; ++f) CHECK(b.face_vertices[4 * f + 2] == centre);
    // Corner k's quad: P_k, M_k, C, M_k-1, where M_k is the middle sample of side k.
    for (uint32_t k = 0; k < n; ++k) {
      CHECK(b.face_vertices[4 * k] == k);
      const auto line = net.polyline(EdgeIndex{k});
      CHECK(b.positions[b.face_vertices[4 * k + 1]] == line[middle_sample(arc_parameters(line))]);
    }
    // The surface: n * 4^2 quads.
    auto s = reconstruct_surface(net, {Method::Fire, 1, 2, Planarity::LeastSquares});
    REQUIRE(s.ok());
    CHECK(s->face_count() == 16 * n);
    CHECK(s->normals.size() == s->positions.size());
  }
}

TEST_CASE("FIRE: a side much longer than its face's mean side gets more pieces, and the faces beside it polygons",
          "[reconstruct][fire]") {
  // Four chords of 30 degrees and one of 240: the long one is 2.3 times the mean side.
  const double d = std::numbers::pi / 6;
  const Mesh net = cornered_polygon_network({0, d, 2 * d, 3 * d, 4 * d}, 17);
  for (uint32_t steps : {1u, 2u}) {
    INFO(steps << " Coons steps");
    const BaseMesh b = base_of(net, {Method::Fire, steps, 2, Planarity::LeastSquares});
    const uint32_t pieces = 1u << steps;
    REQUIRE(b.side_count() == 5);
    for (uint32_t s = 0; s < 5; ++s)
      CHECK(b.side_curve_offsets[s + 1] - b.side_curve_offsets[s] == (s == 4 ? 2 * pieces : pieces));
    // Every base face beside the long side has one finer split point between its corners on it.
    uint32_t pentagons = 0, corners = 0;
    for (uint32_t f = 0; f < b.face_count(); ++f) {
      const uint32_t size = b.face_offsets[f + 1] - b.face_offsets[f];
      CHECK((size == 4 || size == 5));
      pentagons += size == 5;
      corners += size;
    }
    CHECK(pentagons == pieces);
    // Still a disk with every base edge carrying one curve.
    CHECK(int64_t(b.vertex_count()) - int64_t(b.curve_count()) + int64_t(b.face_count()) == 1);
    auto surface = reconstruct_surface(net, {Method::Fire, steps, 2, Planarity::LeastSquares});
    REQUIRE(surface.ok());
    CHECK(surface->face_count() == 4 * corners);
  }
  // The thesis's Coons steps split every side alike.
  const BaseMesh thesis = base_of(net, {Method::Thesis, 1, 2, Planarity::LeastSquares});
  for (uint32_t s = 0; s < thesis.side_count(); ++s) CHECK(thesis.side_curve_offsets[s + 1] - thesis.side_curve_offsets[s] == 2);
}

TEST_CASE("FIRE: sides that run straight on through a corner are one side, split first at that corner",
          "[reconstruct][fire]") {
  // A disc bounded by n arcs of one circle: every corner goes straight on. Sides join in pairs until four
  // are left; a half of a joined side is one base edge, every other side two, and the face four quads.
  for (uint32_t n : {4u, 5u, 6u}) {
    INFO("n = " << n);
    const Mesh net = polygon_network(n);
    const BaseMesh b = base_of(net, {Method::Fire, 1, 2, Planarity::LeastSquares});
    const uint32_t halves = 2 * (n - 4);
    CHECK(b.face_count() == 4);
    check_disk(b);
    CHECK(b.vertex_count() == n + (n - halves) + 1);
    uint32_t one_piece = 0;
    for (uint32_t s = 0; s < b.side_count(); ++s) {
      const uint32_t pieces = b.side_curve_offsets[s + 1] - b.side_curve_offsets[s];
      CHECK((pieces == 1 || pieces == 2));
      one_piece += pieces == 1;
    }
    CHECK(one_piece == halves);
    auto surface = reconstruct_surface(net, {Method::Fire, 1, 2, Planarity::LeastSquares});
    REQUIRE(surface.ok());
    CHECK(surface->face_count() == 4 * 16);
  }
}

TEST_CASE("FIRE: a straight corner joins its sides only where every face of those sides joins them",
          "[reconstruct][fire]") {
  // A 2 x 1 rectangle over [0, 2] x [1, 2] whose bottom runs straight on through (1, 1), below it either
  // one more such rectangle (the vertex has valence 2: both faces join there) or two unit squares (the
  // vertex is a corner of the squares, which split those sides in two, so the rectangle does too).
  auto line = [](const Vec3& a, const Vec3& b) {
    std::vector<Vec3> points;
    for (int i = 0; i <= 8; ++i) points.push_back(a + (b - a) * (i / 8.0));
    return points;
  };
  for (bool squares : {false, true}) {
    INFO((squares ? "two squares below" : "a rectangle below"));
    Mesh net;
    std::vector<Vec3> at{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}, {0, 2, 0}, {2, 2, 0}};
    std::vector<VertexIndex> v;
    for (const Vec3& p : at) v.push_back(net.add_vertex(p));
    auto edge = [&](uint32_t a, uint32_t b) { return net.add_edge(v[a], v[b], line(at[a], at[b])); };
    const EdgeIndex left = edge(3, 4), right = edge(4, 5), top_right = edge(5, 7), top = edge(7, 6), top_left = edge(6, 3);
    const EdgeIndex bottom_left = edge(0, 3), bottom_right = edge(2, 5);
    std::vector<OrientedEdge> upper{make_oriented(left, false), make_oriented(right, false), make_oriented(top_right, false),
                                make_oriented(top, false), make_oriented(top_left, false)};
    if (squares) {
      const EdgeIndex a = edge(0, 1), b = edge(1, 2), middle = edge(1, 4);
      const OrientedEdge first[] = {make_oriented(a, false), make_oriented(middle, false), make_oriented(left, true),
                                make_oriented(bottom_left, true)};
      const OrientedEdge second[] = {make_oriented(b, false), make_oriented(bottom_right, false), make_oriented(right, true),
                                 make_oriented(middle, true)};
      REQUIRE(net.add_face(first) != kNone);
      REQUIRE(net.add_face(second) != kNone);
    } else {
      const EdgeIndex bottom = edge(0, 2);
      const OrientedEdge lower[] = {make_oriented(bottom, false), make_oriented(bottom_right, false), make_oriented(right, true),
                                make_oriented(left, true), make_oriented(bottom_left, true)};
      REQUIRE(net.add_face(lower) != kNone);
    }
    const FaceIndex upper_face = net.add_face(upper);
    REQUIRE(upper_face != kNone);
    REQUIRE(net.validate() == "");
    const BaseMesh b = base_of(net, {Method::Fire, 1, 2, Planarity::LeastSquares});
    check_disk(b);
    uint32_t upper_quads = 0;
    for (uint32_t f = 0; f < b.face_count(); ++f) upper_quads += b.face_source[f] == upper_face;
    CHECK(upper_quads == (squares ? 5u : 4u));
    // The two halves are one base edge each where they join, two where the squares split them.
    uint32_t one_piece = 0;
    for (uint32_t s = 0; s < b.side_count(); ++s) one_piece += b.side_curve_offsets[s + 1] - b.side_curve_offsets[s] == 1;
    CHECK(one_piece == (squares ? 0u : 2u));
    CHECK(b.vertex_count() == (squares ? 8u + 10u + 3u : 7u + 6u + 2u));
  }
}

TEST_CASE("FIRE: a border vertex is a corner only where the border turns", "[reconstruct][fire]") {
  // Two unit squares side by side: the four outer corners turn by 90 degrees, the middle vertices of
  // the long sides go straight on.
  const Mesh grid = grid_network(2, 1, 9, [](double x, double y) { return 0.1 * x * y; });
  const BaseMesh b = base_of(grid, {Method::Fire, 1, 2, Planarity::LeastSquares});
  REQUIRE(b.border_corners.size() == b.vertex_count());
  uint32_t corners = 0;
  for (uint32_t v = 0; v < b.vertex_count(); ++v) {
    const Vec3& p = b.positions[v];
    const bool outer = (p.x() == 0 || p.x() == 2) && (p.y() == 0 || p.y() == 1);
    INFO("base vertex " << v << " at " << p.transpose());
    CHECK(b.border_corners[v] == (outer ? 1 : 0));
    corners += b.border_corners[v];
  }
  CHECK(corners == 4);
  // A face bounded by arcs of one circle has a smooth border: no corners at all, where EdgeAndCorner
  // made each meeting point of two arcs a corner.
  const Mesh disk = polygon_network(4);
  const BaseMesh d = base_of(disk, {Method::Fire, 1, 2, Planarity::LeastSquares});
  for (uint8_t flag : d.border_corners) CHECK(flag == 0);
  // The thesis pipeline keeps Catmull-Clark's own rule.
  CHECK(base_of(disk, {Method::Thesis, 1, 2, Planarity::LeastSquares}).border_corners.empty());
}

TEST_CASE("FIRE: a border turn no larger than the noise's own turning is no corner", "[reconstruct][fire][noise]") {
  // A 4 x 2 grid whose bottom border is bent at its middle vertex by 31 degrees, more than the 30 of an exact
  // network, the top border straight.
  const double dip = 2 * std::tan(15.5 * std::numbers::pi / 180);
  Mesh net = grid_network(4, 2, 17, [](double x, double y) { return 0.05 * x * y; });
  auto bend = [&](Vec3 p) {
    p.y() -= dip * (1 - std::abs(p.x() - 2) / 2) * (1 - p.y() / 2);
    return p;
  };
  for (VertexIndex v{0}; v < net.vertex_slots(); ++v) net.vertices.position.set(v, bend(net.vertices.position[v]));
  for (uint32_t i = 0; i < uint32_t(net.points.size()); ++i) net.points.set(i, bend(net.points[i]));
  const Vec3 kink(2, -dip, 0);
  auto kink_is_corner = [&](const Mesh& m) {
    const BaseMesh b = base_of(m, {Method::Fire, 1, 2, Planarity::LeastSquares});
    for (uint32_t v = 0; v < b.vertex_count(); ++v)
      if ((b.positions[v] - kink).norm() < 1e-9) return b.border_corners[v] != 0;
    FAIL("no base vertex at the kink");
    return false;
  };
  CHECK(tangent_spread_deg(net) < 0.5);
  CHECK(kink_is_corner(net));
  // Every curve bowed up by a smooth bump, as a tracked pen errs along a stroke: the curves now leave their
  // vertices 4.4 degrees out of one plane (the median), and the kink, tilted up on both sides (a turn of
  // about 32.4 degrees now), is within what that noise makes.
  for (EdgeIndex e{0}; e < net.edge_slots(); ++e) {
    const uint32_t first = net.edges.point_offset[e], count = net.edges.point_count[e];
    for (uint32_t s = 1; s + 1 < count; ++s)
      net.points.set(first + s, net.points[first + s] + Vec3(0, 0, 0.03 * std::sin(std::numbers::pi * s / (count - 1))));
  }
  CHECK(tangent_spread_deg(net) == Approx(4.4).margin(0.1));
  CHECK_FALSE(kink_is_corner(net));
}

TEST_CASE("FIRE: a noisy border's turn is read past the pen's rest at a vertex", "[reconstruct][fire][noise]") {
  // A 4 x 2 grid of noisy curves. Where two border strokes meet, the pen rests, and the curves' samples there
  // jitter within a noise deviation of the vertex over a long stretch of their arc (the simulated pawn's base):
  // read inside that rest, the border would turn any way. The straight bottom's middle (2, 0) stays smooth, and
  // the grid's corner (0, 0) a corner, with such rests at both.
  const uint32_t samples = 41, rest = 14;
  Mesh net = grid_network(4, 2, samples,
                          [](double x, double y) { return 0.05 * x * y + 0.004 * std::sin(97 * x + 53 * y); });
  REQUIRE(fit_noise(net) > kExactCurveNoise);
  // About the deviation the surface reads the noise as (curve_noise_deviation; the curves are 1 long).
  const double deviation =
      std::max(fit_noise(net), std::sin(tangent_spread_deg(net) * std::numbers::pi / 180) * kTangentReach);
  auto is_corner = [&](const Vec3& at) {
    const BaseMesh b = base_of(net, {Method::Fire, 1, 2, Planarity::LeastSquares});
    for (uint32_t v = 0; v < b.vertex_count(); ++v)
      if ((b.positions[v] - at).norm() < 1e-9) return b.border_corners[v] != 0;
    FAIL("no base vertex at " << at.transpose());
    return false;
  };
  const Vec3 middle = net.vertices.position[2], corner = net.vertices.position[0];
  REQUIRE(!is_corner(middle));
  REQUIRE(is_corner(corner));
  // The rest: the curve's samples nearest the vertex, each a deviation from it, turning a quarter round from one
  // to the next, in and out of the surface as a hand's tremor would.
  auto rest_at = [&](uint32_t e, bool at_start) {
    const uint32_t first = net.edges.point_offset[e];
    const Vec3 vertex = net.points[at_start ? first : first + samples - 1];
    for (uint32_t k = 1; k <= rest; ++k) {
      const double angle = std::numbers::pi / 2 * k;
      const Vec3 off = deviation * Vec3(0.3 * std::cos(angle), std::sin(angle), 0.5 * std::cos(angle));
      net.points.set(at_start ? first + k : first + samples - 1 - k, vertex + off);
    }
  };
  rest_at(1, false);  // the bottom's second curve ends at (2, 0)
  rest_at(2, true);   // its third begins there
  rest_at(0, true);   // the bottom's first curve begins at (0, 0)
  rest_at(4 * 3, true);  // and the left border's first curve
  REQUIRE(net.validate() == "");
  CHECK_FALSE(is_corner(middle));
  CHECK(is_corner(corner));
}

TEST_CASE("FIRE: a straight corner joins its sides only beyond the noise's own turning", "[reconstruct][fire][noise]") {
  // A 4 x 4 grid whose first two bottom faces are one: its bottom runs straight on through (1, 0), a border
  // vertex of valence 2, which the face joins (five base faces for its six corners); (1, 1) is a corner of
  // the faces above, which split the sides there, so the face keeps it.
  Mesh net = grid_network(4, 4, 17, [](double x, double y) { return 0.05 * x * y; });
  const uint32_t nx = 4, vertical = 5 * nx;
  net.remove_face(FaceIndex{0});
  net.remove_face(FaceIndex{1});
  net.remove_edge(EdgeIndex{vertical + 1});
  const OrientedEdge loop[] = {make_oriented(EdgeIndex{0}, false),      make_oriented(EdgeIndex{1}, false),
                               make_oriented(EdgeIndex{vertical + 2}, false), make_oriented(EdgeIndex{nx + 1}, true),
                               make_oriented(EdgeIndex{nx}, true),        make_oriented(EdgeIndex{vertical}, true)};
  const FaceIndex merged = net.add_face(loop);
  REQUIRE(merged != kNone);
  REQUIRE(net.validate() == "");
  auto base_faces = [&](const Mesh& m) {
    const BaseMesh b = base_of(m, {Method::Fire, 1, 2, Planarity::LeastSquares});
    return std::count(b.face_source.begin(), b.face_source.end(), merged);
  };
  CHECK(tangent_spread_deg(net) < 0.5);
  CHECK(base_faces(net) == 5);
  // Every curve but the two joined ones bowed up, by one to three times a height, as a tracked pen errs along
  // a stroke: the curves leave their vertices out of one plane (tangent_spread_deg), and a corner counts as
  // straight only where it turns by less than 20 degrees less that spread.
  auto bowed = [&](double height) {
    Mesh m = net;
    for (EdgeIndex e{2}; e < m.edge_slots(); ++e) {
      if (!m.edge_alive(e)) continue;
      const uint32_t first = m.edges.point_offset[e], count = m.edges.point_count[e];
      for (uint32_t s = 1; s + 1 < count; ++s)
        m.points.set(first + s, m.points[first + s] + Vec3(0, 0, height * (1 + e % 3) * std::sin(std::numbers::pi * s / (count - 1))));
    }
    return m;
  };
  const Mesh slightly = bowed(0.01), strongly = bowed(0.15);
  INFO("tangent spread " << tangent_spread_deg(slightly) << " and " << tangent_spread_deg(strongly) << " degrees");
  CHECK(tangent_spread_deg(slightly) < kStraightCornerTurn / 2);
  CHECK(base_faces(slightly) == 5);
  CHECK(tangent_spread_deg(strongly) > kStraightCornerTurn);
  CHECK(base_faces(strongly) == 6);
}

TEST_CASE("the worst base quad's aspect: 1 for a square, 1/w for a 1 x w rectangle", "[reconstruct]") {
  BaseMesh b;
  b.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}, {2, 0.25, 0}, {1, 0.25, 0}};
  b.face_vertices = {0, 1, 2, 3};
  b.face_offsets = {0, 4};
  CHECK(worst_quad_aspect(b) == Approx(1.0));
  b.face_vertices.insert(b.face_vertices.end(), {1, 4, 5, 6});
  b.face_offsets.push_back(8);
  CHECK(worst_quad_aspect(b) == Approx(4.0));
  b.positions[5] = {3, 0, 0};  // all four on one line: no area
  b.positions[6] = {1.5, 0, 0};
  CHECK(std::isinf(worst_quad_aspect(b)));
}

TEST_CASE("the fit's shape term weighs the vertices of thin base quads only, at most 1", "[reconstruct][fit]") {
  BaseMesh b;
  // A unit square and a 1 x w rectangle beside it, sharing the edge 1-2.
  b.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {1.25, 0, 0}, {1.25, 1, 0}};
  b.face_vertices = {0, 1, 2, 3, 1, 4, 5, 2};
  b.face_offsets = {0, 4, 8};
  FitWeights weights;
  weights.shape_aspect = 3;
  // w = 0.25: aspect 4, excess 4 / 3 - 1, squared.
  std::vector<double> w = shape_weights(b, weights);
  CHECK(w[0] == 0);
  CHECK(w[3] == 0);
  for (uint32_t v : {1u, 2u, 4u, 5u}) CHECK(w[v] == Approx(1.0 / 9.0));
  // w = 0.1: aspect 10, capped.
  b.positions[4].x() = b.positions[5].x() = 1.1;
  w = shape_weights(b, weights);
  CHECK(w[4] == 1.0);
  weights.shape = 0;
  w = shape_weights(b, weights);
  CHECK(std::all_of(w.begin(), w.end(), [](double x) { return x == 0; }));
}

TEST_CASE("FIRE: the fitted limit surface passes through the drawn samples", "[reconstruct][fire][fit]") {
  // Curves sampled on the limit surface of a 4 x 4 control grid at its level-3 vertices: the FIRE base
  // mesh has the grid's topology, so a surface through every sample exists.
  const Mesh net = limit_grid_network(2, 3, [](double x, double y) {
    return 0.12 * (x - 2) * (x - 2) - 0.08 * (y - 1.5) * (y - 1.5) + 0.05 * x * y;
  });
  auto worst_distance = [&](const SurfaceMesh& s) {
    double worst = 0;
    for (const Vec3& p : net.points.values()) worst = std::max(worst, nearest_distance(s.positions, p));
    return worst;
  };
  Options exact;
  exact.fairness = 1e-6;  // the fairness only chooses among the surfaces the curves allow
  ReconstructionState state;
  SurfaceMesh s;
  REQUIRE(reconstruct_update(net, exact, state, s).ok());
  CHECK(state.base().vertex_count() == 25);
  CHECK(state.base().face_count() == 16);
  CHECK(worst_distance(s) < 1e-6);
  CHECK(state.last_update().fit_rms < 1e-7);
  // The default fairness trades a little of that for smooth interiors where curves say little; the
  // model is 4 units wide.
  auto smooth = reconstruct_surface(net, Options{});
  REQUIRE(smooth.ok());
  CHECK(worst_distance(*smooth) < 1e-4);
  // The thesis pipeline does not pass through them: Catmull-Clark shrinks the base mesh.
  auto thesis = reconstruct_surface(net, {Method::Thesis, 1, 3, Planarity::LeastSquares});
  REQUIRE(thesis.ok());
  CHECK(worst_distance(*thesis) > 1e-2);
}

TEST_CASE("bad networks and options are rejected with the element named", "[reconstruct][errors]") {
  auto error_of = [](const Mesh& net, Options o) {
    auto r = reconstruct_surface(net, o);
    REQUIRE_FALSE(r.ok());
    return r.error();
  };
  const Options thesis{Method::Thesis, 1, 3, Planarity::LeastSquares}, fire{};
  CHECK_THAT(error_of(polygon_network(2), thesis), Catch::Contains("face 0 has 2 edges"));
  CHECK(reconstruct_surface(polygon_network(2), fire).ok());
  CHECK_THAT(error_of(polygon_network(4), {Method::Fire, 0, 3, Planarity::LeastSquares}), Catch::Contains("Coons steps"));
  CHECK_THAT(error_of(polygon_network(4), {Method::Fire, 1, 9, Planarity::LeastSquares}), Catch::Contains("subdivision level"));
  CHECK_THAT(error_of(Mesh{}, fire), Catch::Contains("no faces"));
  Options unfair;
  unfair.fairness = std::nan("");
  CHECK_THAT(error_of(polygon_network(4), unfair), Catch::Contains("fairness weight"));

  // Coincident consecutive points.
  Mesh repeated = polygon_network(3);
  repeated.points.set(repeated.edges.point_offset[1] + 3, repeated.polyline(EdgeIndex{1})[2]);
  CHECK_THAT(error_of(repeated, fire), Catch::Contains("edge 1's polyline has coincident consecutive points 2 and 3"));

  // NaN.
  Mesh nan = polygon_network(3);
  nan.points.set(nan.edges.point_offset[2] + 4, Vec3(0, std::nan(""), 0));
  CHECK_THAT(error_of(nan, fire), Catch::Contains("edge 2 has a non-finite polyline point 4"));

  // Two corners at one point; and a polyline of zero length between them.
  Mesh pinched;
  const VertexIndex a = pinched.add_vertex({0, 0, 0}), b = pinched.add_vertex({1, 0, 0}), c = pinched.add_vertex({0, 0, 0});
  const EdgeIndex e0 = pinched.add_edge(a, b, std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}});
  const EdgeIndex e1 = pinched.add_edge(b, c, std::vector<Vec3>{{1, 0, 0}, {0.5, 0.5, 0}, {0, 0, 0}});
  const EdgeIndex e2 = pinched.add_edge(c, a, std::vector<Vec3>{{0, 0, 0}, {-0.5, -0.5, 0}, {0, 0, 0}});
  REQUIRE(pinched.add_face(std::vector<OrientedEdge>{make_oriented(e0, false), make_oriented(e1, false), make_oriented(e2, false)}) != kNone);
  CHECK_THAT(error_of(pinched, fire), Catch::Contains("face 0 has coincident corners: vertices 0 and 2"));
  Mesh flat = pinched;
  for (uint32_t k = 0; k < 3; ++k) flat.points.set(flat.edges.point_offset[e2] + k, Vec3(0, 0, 0));
  CHECK_THAT(error_of(flat, fire), Catch::Contains("edge 2's polyline has zero length"));
}
