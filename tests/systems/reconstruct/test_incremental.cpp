// Incremental reconstruction: an edit recomputes only the faces it touched and their neighbours, and
// the result equals a reconstruction from scratch bit for bit.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>

#include <Eigen/Geometry>

#include "networks.hpp"
#include "systems/reconstruct/fit.hpp"
#include "systems/reconstruct/reconstruct.hpp"
#include "systems/split/edit.hpp"

using namespace fire;
using namespace fire::reconstruct;
using namespace fire::test;

namespace {

double height(double x, double y) { return 0.6 * std::sin(0.4 * x) * std::cos(0.5 * y) + 0.03 * x * y; }


void check_equals_full_rebuild(const Mesh& net, const Options& options, const SurfaceMesh& incremental) {
  auto full = reconstruct_surface(net, options);
  REQUIRE(full.ok());
  CHECK(same_bytes(incremental.positions, full->positions));
  CHECK(same_bytes(incremental.normals, full->normals));
  CHECK(same_bytes(incremental.face_offsets, full->face_offsets));
  CHECK(same_bytes(incremental.face_vertices, full->face_vertices));
}

// One frame's update; the next edit belongs to the next frame, as in a session.
void update(Mesh& net, const Options& options, ReconstructionState& state, SurfaceMesh& surface) {
  Status s = reconstruct_update(net, options, state, surface);
  INFO(s.error);
  REQUIRE(s.ok());
  net.begin_frame(net.frame() + 1);
}

}  // namespace

TEST_CASE("adding, moving and deleting a curve on a 200-face network", "[reconstruct][incremental]") {
  const uint32_t nx = 20, ny = 10;
  for (Method method : {Method::Fire, Method::Thesis}) {
    INFO((method == Method::Fire ? "fire" : "thesis"));
    const Options options{method, 1, 2, Planarity::LeastSquares};
    Mesh net = grid_network(nx, ny, 9, height);
    REQUIRE(net.face_count() == 200);
    ReconstructionState state;
    SurfaceMesh surface;
    update(net, options, state, surface);
    CHECK(state.last_update().faces_recomputed == 200);

    // Nothing changed: nothing is recomputed and the surface is the same.
    const SurfaceMesh before = surface;
    update(net, options, state, surface);
    CHECK(state.last_update().faces_recomputed == 0);
    CHECK(state.last_update().edges_recomputed == 0);
    CHECK_FALSE(state.last_update().topology_rebuilt);
    CHECK(same_bytes(surface.positions, before.positions));

    // A curve across face (7, 4) from the middle of its bottom edge to the middle of its top edge.
    const uint32_t i = 7, j = 4, face = j * nx + i;
    EditCommand add;
    add.kind = EditKind::SplitFace;
    add.face = FaceIndex{face};
    add.start = {EdgeIndex{j * nx + i}, 4};
    add.end = {EdgeIndex{(j + 1) * nx + i}, 4};
    for (int k = 0; k <= 8; ++k) add.points.emplace_back(i + 0.5, j + k / 8.0, height(i + 0.5, j + k / 8.0));
    REQUIRE(execute_edit(net, add).ok());
    REQUIRE(net.face_count() == 201);
    update(net, options, state, surface);
    // Touched: the split face's two halves and the faces below and above it, whose edges were split (4).
    // Their edges are tagged, so the faces across them are recomputed too: left and right of each of the
    // three faces in the column (6), below the one below and above the one above (2).
    CHECK(state.last_update().faces_recomputed == 4 + 6 + 2);
    CHECK(state.last_update().topology_rebuilt);
    check_equals_full_rebuild(net, options, surface);

    // Moving an interior vertex: its four faces, a back-substitution for the FIRE fit.
    const VertexIndex v{3 * (nx + 1) + 12};
    net.move_vertex(v, net.vertices.position[v] + Vec3(0, 0, 0.05));
    update(net, options, state, surface);
    CHECK(state.last_update().faces_recomputed == 4);
    CHECK(state.last_update().edges_recomputed == 4);
    CHECK_FALSE(state.last_update().topology_rebuilt);
    check_equals_full_rebuild(net, options, surface);

    // Moved most of the way across its right-hand faces, it leaves them thin: their base quads' shape
    // weights (FitWeights::shape) change with the same topology, and the fit, factorized again, still
    // equals a full rebuild.
    const std::vector<double> square = shape_weights(state.base(), FitWeights{});
    net.move_vertex(v, net.vertices.position[v] + Vec3(0.8, 0, 0));
    update(net, options, state, surface);
    CHECK_FALSE(state.last_update().topology_rebuilt);
    if (method == Method::Fire) CHECK(shape_weights(state.base(), FitWeights{}) != square);
    check_equals_full_rebuild(net, options, surface);

    // Deleting the curve again.
    EdgeIndex curve;
    for (EdgeIndex e{0}; e < net.edge_slots(); ++e)
      if (net.edge_alive(e) && net.polyline(e).front().x() == i + 0.5 && net.polyline(e).back().x() == i + 0.5) curve = e;
    REQUIRE(curve != kNone);
    EditCommand remove;
    remove.kind = EditKind::DeleteCurve;
    remove.edge = curve;
    REQUIRE(execute_edit(net, remove).ok());
    REQUIRE(net.face_count() == 200);
    update(net, options, state, surface);
    // The merged face and the two faces whose split edges were joined again (3), and across their
    // tagged edges: left and right of each (6), below the lower one and above the upper one (2).
    CHECK(state.last_update().faces_recomputed == 3 + 6 + 2);
    check_equals_full_rebuild(net, options, surface);
  }
}

TEST_CASE("a noisy network's fit follows its noise, and a move that changes the estimate refactorizes, equal to a rebuild",
          "[reconstruct][incremental][noise]") {
  // Every curve carries a ripple a little longer than its sample spacing (1/19): noise to the estimate.
  auto noisy = [](double x, double y) { return height(x, y) + 0.004 * std::sin(97 * x + 53 * y); };
  Mesh net = grid_network(6, 4, 20, noisy);
  const Options options;
  const double noise = noise_estimate(net);
  CHECK(noise > kExactCurveNoise);
  CHECK(fit_fairness(options, noise) > options.fairness);
  CHECK(fit_fairness(options, noise) <= kNoisyFairness);
  // The same curves without the ripple are exact; an explicit weight is used as is.
  CHECK(fit_fairness(options, noise_estimate(grid_network(6, 4, 20, height))) == options.fairness);
  // Exact curves are read on the smooth curve through their samples, noisy ones along their chords.
  CHECK(fit_targets(noise_estimate(grid_network(6, 4, 20, height))) == Sampling::Smooth);
  CHECK(fit_targets(noise) == Sampling::Linear);
  Options explicit_weight;
  explicit_weight.fairness_from_noise = false;
  CHECK(fit_fairness(explicit_weight, noise) == explicit_weight.fairness);
  // Noisier curves than the plateau's: the fairness grows on from it, with the square of the noise.
  CHECK(fit_fairness(options, kNoisierCurves) == kNoisyFairness);
  CHECK(fit_fairness(options, 2 * kNoisierCurves) == Approx(4 * kNoisyFairness));
  CHECK(fit_fairness(options, 10 * kNoisierCurves) == kNoisiestFairness);

  ReconstructionState state;
  SurfaceMesh surface;
  update(net, options, state, surface);
  check_equals_full_rebuild(net, options, surface);
  const VertexIndex v{2 * 7 + 3};  // an interior vertex
  net.move_vertex(v, net.vertices.position[v] + Vec3(0.3, 0.2, 0.1));
  CHECK(fit_fairness(options, noise_estimate(net)) != fit_fairness(options, noise));
  update(net, options, state, surface);
  CHECK_FALSE(state.last_update().topology_rebuilt);
  check_equals_full_rebuild(net, options, surface);
}

namespace {

// How far the farthest of `points` lies from the line through a and b.
double farthest_from_chord(std::span<const Vec3> points, const Vec3& a, const Vec3& b) {
  double farthest = 0;
  for (const Vec3& q : points) farthest = std::max(farthest, (q - a).cross(b - a).norm() / (b - a).norm());
  return farthest;
}

// Per side of `base` (its drawn curves in order), how far its points lie from the chord between its ends
// at most.
std::vector<double> departures(const BaseMesh& base) {
  std::vector<double> out;
  for (uint32_t s = 0; s < base.side_count(); ++s) {
    const uint32_t first = base.side_curve_offsets[s], end = base.side_curve_offsets[s + 1];
    const Vec3 a = base.curve(first).front(), b = base.curve(end - 1).back();
    double farthest = 0;
    for (uint32_t c = first; c < end; ++c) farthest = std::max(farthest, farthest_from_chord(base.curve(c), a, b));
    out.push_back(farthest);
  }
  return out;
}

}  // namespace

TEST_CASE("a noisy curve as short as its noise is taken nearer its chord, and a change of that redoes its faces, "
          "equal to a rebuild",
          "[reconstruct][incremental][noise]") {
  auto noisy = [](double x, double y) { return height(x, y) + 0.03 * std::sin(97 * x + 53 * y); };
  // The grid's fourth column of faces squeezed to 0.3 of its width: 2 of its 5 horizontal curves also end
  // level and reach less than kShortCurveNoises deviations of the noise from their ends; the others climb
  // farther.
  auto squeeze = [](Vec3 p) {
    p.x() = p.x() <= 3 ? p.x() * 3.7 / 3 : p.x() <= 4 ? 3.7 + (p.x() - 3) * 0.3 : p.x();
    return p;
  };
  auto squeezed = [&](const Height& h) {
    Mesh net = grid_network(6, 4, 20, h);
    for (VertexIndex v{0}; v < net.vertex_slots(); ++v) net.vertices.position.set(v, squeeze(net.vertices.position[v]));
    for (uint32_t i = 0; i < uint32_t(net.points.size()); ++i) net.points.set(i, squeeze(net.points[i]));
    return net;
  };
  const Options options;
  SurfaceMesh surface;

  // Exact curves, however short, are followed as drawn.
  Mesh exact = squeezed(height);
  ReconstructionState exact_state;
  update(exact, options, exact_state, surface);
  CHECK(exact_state.short_curves() == 0);

  Mesh net = squeezed(noisy);
  REQUIRE(fit_noise(net) > kExactCurveNoise);
  ReconstructionState state;
  update(net, options, state, surface);
  check_equals_full_rebuild(net, options, surface);
  CHECK(state.short_curves() == 2);
  // The surface's polylines lie no farther from their chords than the drawn ones. Every curve is taken straight
  // near its ends (kEndStraightNoises), border curves too, so most border curves lie nearer their chords (only
  // the short one would, if border curves stayed as drawn). The base's drawn curves come in edge order; every
  // edge of the grid is drawn.
  const std::vector<double> before = departures(state.base());
  REQUIRE(before.size() == net.edge_count());
  auto border = [&](uint32_t e) { return net.edges.face[e][0] == kNone || net.edges.face[e][1] == kNone; };
  uint32_t border_curves = 0, nearer_border = 0, partly = 0;
  for (EdgeIndex e{0}; e < net.edge_count(); ++e) {
    const auto line = net.polyline(e);
    const double drawn = farthest_from_chord(line, line.front(), line.back());
    CHECK(before[e] <= drawn);
    border_curves += border(e);
    if (border(e) && before[e] < drawn) ++nearer_border;
    if (before[e] > 0 && before[e] < drawn) ++partly;
  }
  CHECK(nearer_border > border_curves / 2);
  REQUIRE(partly >= 1);  // a short curve keeps part of its shape, so the move below changes it

  // A vertex far from them raised: the curves' mean length, and with it how much of the short curves'
  // shape the surface takes and how far every curve is taken straight, change; so their faces are redone too:
  // every curve's but the raised vertex's own (redone as moved). The border's corners stay where they were.
  const VertexIndex far{3 * 7 + 5};
  const std::vector<EdgeIndex> at_far = net.vertex_edges(far);
  uint32_t elsewhere = 0;
  for (uint32_t e = 0; e < net.edge_count(); ++e)
    elsewhere += std::find(at_far.begin(), at_far.end(), e) == at_far.end();
  net.move_vertex(far, net.vertices.position[far] + Vec3(0, 0, 0.3));
  update(net, options, state, surface);
  CHECK_FALSE(state.last_update().topology_rebuilt);
  CHECK(state.last_update().edges_recomputed > at_far.size());
  CHECK(state.last_update().edges_rescaled == elsewhere);
  CHECK(departures(state.base()) != before);
  check_equals_full_rebuild(net, options, surface);
}

TEST_CASE("smooth curves whose tangents disagree where they meet are fitted as noisy ones", "[reconstruct][noise]") {
  Mesh net = grid_network(6, 4, 20, height);
  CHECK(tangent_spread_deg(net) < 0.6);
  CHECK(fit_noise(net) == noise_estimate(net));
  // Every curve bowed up by a smooth bump of 3 % of its length, as a tracked pen errs smoothly along a
  // stroke: each stays smooth, but the curves now leave every vertex out of one plane, by 5.4 degrees
  // where four meet and 4.4 on the border, where three do (the median).
  for (EdgeIndex e{0}; e < net.edge_slots(); ++e) {
    const uint32_t first = net.edges.point_offset[e], count = net.edges.point_count[e];
    for (uint32_t s = 1; s + 1 < count; ++s)
      net.points.set(first + s, net.points[first + s] + Vec3(0, 0, 0.03 * std::sin(std::numbers::pi * s / (count - 1))));
  }
  CHECK(noise_estimate(net) <= kExactCurveNoise);
  CHECK(tangent_spread_deg(net) == Approx(4.4).margin(0.1));
  CHECK(fit_fairness(Options{}, fit_noise(net)) == Approx(kNoisyFairness));
}

TEST_CASE("noisy curves meeting at an inner vertex of valence 2 are one side of its faces, exact ones keep it, "
          "and a change of that equals a rebuild",
          "[reconstruct][incremental][noise]") {
  auto noisy = [](double x, double y) { return height(x, y) + 0.03 * std::sin(97 * x + 53 * y); };
  const Options options;
  // An inner horizontal curve of a 6 x 4 grid split at its 6th of 20 samples: a vertex of valence 2 between
  // two faces, which become pentagons.
  const EdgeIndex edge{2 * 6 + 2};
  auto with_vertex = [&](const Height& h, VertexIndex& v) {
    Mesh net = grid_network(6, 4, 20, h);
    REQUIRE_FALSE(net.is_border_edge(edge));
    v = split_edge(net, edge, 5);
    REQUIRE(net.valence(v) == 2);
    net.begin_frame(net.frame() + 1);
    return net;
  };
  auto has_vertex_at = [](const BaseMesh& b, const Vec3& p) {
    return std::any_of(b.positions.begin(), b.positions.end(), [&](const Vec3& q) { return q == p; });
  };
  SurfaceMesh surface;
  VertexIndex v;

  // Exact: the vertex is a base vertex and each pentagon gives 5 quads.
  Mesh exact = with_vertex(height, v);
  ReconstructionState exact_state;
  update(exact, options, exact_state, surface);
  CHECK(exact_state.joined_vertices() == 0);
  CHECK(has_vertex_at(exact_state.base(), exact.vertices.position[v]));
  CHECK(exact_state.base().face_count() == 4 * 24 + 2);

  // Noisy: the two curves are one side, split as the curve they were; the base mesh is the unsplit grid's.
  Mesh plain = grid_network(6, 4, 20, noisy);
  REQUIRE(fit_noise(plain) > kExactCurveNoise);
  const BaseMesh unsplit = [&] {
    ReconstructionState s;
    SurfaceMesh out;
    update(plain, options, s, out);
    return s.base();
  }();
  Mesh net = with_vertex(noisy, v);
  ReconstructionState state;
  update(net, options, state, surface);
  check_equals_full_rebuild(net, options, surface);
  CHECK(state.joined_vertices() == 1);
  const BaseMesh joined = state.base();
  CHECK_FALSE(has_vertex_at(joined, net.vertices.position[v]));
  CHECK(joined.face_count() == unsplit.face_count());
  CHECK(joined.vertex_count() == unsplit.vertex_count());
  std::vector<Vec3> a = joined.curve_points, b = unsplit.curve_points;
  auto lexical = [](const Vec3& p, const Vec3& q) { return std::lexicographical_compare(p.data(), p.data() + 3, q.data(), q.data() + 3); };
  std::sort(a.begin(), a.end(), lexical);
  std::sort(b.begin(), b.end(), lexical);
  CHECK(a == b);  // the same polylines, split at the same samples

  // One of the two curves made a crease: the vertex is kept again, then joined again once it is smooth.
  // Only the two faces of the side are redone each time.
  const std::vector<EdgeIndex> edges = net.vertex_edges(v);
  REQUIRE(edges.size() == 2);
  net.set_edge_flag(edges[0], kSharpEdge, true);
  update(net, options, state, surface);
  check_equals_full_rebuild(net, options, surface);
  CHECK(state.joined_vertices() == 0);
  CHECK(has_vertex_at(state.base(), net.vertices.position[v]));
  CHECK(state.last_update().faces_recomputed == 2);
  net.set_edge_flag(edges[0], kSharpEdge, false);
  update(net, options, state, surface);
  check_equals_full_rebuild(net, options, surface);
  CHECK(state.joined_vertices() == 1);
  CHECK(state.last_update().faces_recomputed == 2);
  CHECK(same_bytes(state.base().curve_points, joined.curve_points));
}
