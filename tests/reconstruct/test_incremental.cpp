// Incremental reconstruction: an edit recomputes only the faces it touched and their neighbours, and
// the result equals a reconstruction from scratch bit for bit.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

#include "networks.hpp"
#include "systems/reconstruct/fit.hpp"
#include "systems/reconstruct/reconstruct.hpp"
#include "systems/split/edit.hpp"

using namespace fire;
using namespace fire::reconstruct;
using namespace fire::test;

namespace {

double height(double x, double y) { return 0.6 * std::sin(0.4 * x) * std::cos(0.5 * y) + 0.03 * x * y; }

template <class T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

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
  for (Method method : {Method::fire, Method::thesis}) {
    INFO((method == Method::fire ? "fire" : "thesis"));
    const Options options{method, 1, 2, Planarity::least_squares};
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
    add.face = face;
    add.start = {j * nx + i, 4};
    add.end = {(j + 1) * nx + i, 4};
    for (int k = 0; k <= 8; ++k) add.points.emplace_back(i + 0.5, j + k / 8.0, height(i + 0.5, j + k / 8.0));
    REQUIRE(execute_edit(net, add).ok);
    REQUIRE(net.face_count() == 201);
    update(net, options, state, surface);
    // Touched: the split face's two halves and the faces below and above it, whose edges were split (4).
    // Their edges are tagged, so the faces across them are recomputed too: left and right of each of the
    // three faces in the column (6), below the one below and above the one above (2).
    CHECK(state.last_update().faces_recomputed == 4 + 6 + 2);
    CHECK(state.last_update().topology_rebuilt);
    check_equals_full_rebuild(net, options, surface);

    // Moving an interior vertex: its four faces, a back-substitution for the FIRE fit.
    const uint32_t v = 3 * (nx + 1) + 12;
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
    if (method == Method::fire) CHECK(shape_weights(state.base(), FitWeights{}) != square);
    check_equals_full_rebuild(net, options, surface);

    // Deleting the curve again.
    uint32_t curve = kNone;
    for (uint32_t e = 0; e < net.edge_slots(); ++e)
      if (net.edge_alive(e) && net.polyline(e).front().x() == i + 0.5 && net.polyline(e).back().x() == i + 0.5) curve = e;
    REQUIRE(curve != kNone);
    EditCommand remove;
    remove.kind = EditKind::DeleteCurve;
    remove.edge = curve;
    REQUIRE(execute_edit(net, remove).ok);
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
  const uint32_t v = 2 * 7 + 3;  // an interior vertex
  net.move_vertex(v, net.vertices.position[v] + Vec3(0.3, 0.2, 0.1));
  CHECK(fit_fairness(options, noise_estimate(net)) != fit_fairness(options, noise));
  update(net, options, state, surface);
  CHECK_FALSE(state.last_update().topology_rebuilt);
  check_equals_full_rebuild(net, options, surface);
}

TEST_CASE("a noisy curve as short as its noise weighs less, and a change of that weight refactorizes, equal to a rebuild",
          "[reconstruct][incremental][noise]") {
  auto noisy = [](double x, double y) { return height(x, y) + 0.03 * std::sin(97 * x + 53 * y); };
  // The grid's fourth column of faces squeezed to 1/20 of its width: its 5 horizontal curves are 0.05 wide,
  // and 2 of them also end level (the other 3 climb 0.09 to 0.12, more than 16 noise deviations).
  auto squeeze = [](Vec3 p) {
    p.x() = p.x() <= 3 ? p.x() * 3.95 / 3 : p.x() <= 4 ? 3.95 + (p.x() - 3) * 0.05 : p.x();
    return p;
  };
  Mesh net = grid_network(6, 4, 20, noisy);
  for (uint32_t v = 0; v < net.vertex_slots(); ++v) net.vertices.position.set(v, squeeze(net.vertices.position[v]));
  for (uint32_t i = 0; i < uint32_t(net.points.size()); ++i) net.points.set(i, squeeze(net.points[i]));
  const Options options;
  const double noise = fit_noise(net);
  REQUIRE(noise > kExactCurveNoise);
  REQUIRE(fit_fairness(options, noise) == kNoisyFairness);
  auto weights_of = [&](const Mesh& m, const BaseMesh& base) {
    double length = 0;
    uint32_t lines = 0;
    for (uint32_t e = 0; e < m.edge_slots(); ++e) {
      if (!m.edge_alive(e)) continue;
      for (size_t i = 1; i < m.polyline(e).size(); ++i) length += (m.polyline(e)[i] - m.polyline(e)[i - 1]).norm();
      ++lines;
    }
    FitWeights w;
    w.short_curve = kShortCurveNoises * fit_noise(m) * length / lines;
    return curve_weights(base, w);
  };

  ReconstructionState state;
  SurfaceMesh surface;
  update(net, options, state, surface);
  check_equals_full_rebuild(net, options, surface);
  // Exact curves (no short_curve) all weigh 1; here the short curves alone weigh less.
  const std::vector<double> plain = curve_weights(state.base(), FitWeights{});
  CHECK(plain.size() == net.edge_count());
  CHECK(std::all_of(plain.begin(), plain.end(), [](double w) { return w == 1; }));
  const std::vector<double> before = weights_of(net, state.base());
  REQUIRE(before.size() == plain.size());
  CHECK(std::count_if(before.begin(), before.end(), [](double w) { return w < 1; }) == 2);
  CHECK(*std::min_element(before.begin(), before.end()) > 0);

  // A vertex far from it raised: the curves' mean length, and with it the short curve's weight, change;
  // the fairness (on its plateau) and the thin quads' shape weights do not. The fit is factorized again.
  const uint32_t far = 3 * 7 + 5;
  const std::vector<double> shape = shape_weights(state.base(), FitWeights{});
  net.move_vertex(far, net.vertices.position[far] + Vec3(0, 0, 0.3));
  update(net, options, state, surface);
  CHECK_FALSE(state.last_update().topology_rebuilt);
  REQUIRE(fit_fairness(options, fit_noise(net)) == kNoisyFairness);
  REQUIRE(shape_weights(state.base(), FitWeights{}) == shape);
  REQUIRE(weights_of(net, state.base()) != before);
  check_equals_full_rebuild(net, options, surface);
}

TEST_CASE("smooth curves whose tangents disagree where they meet are fitted as noisy ones", "[reconstruct][noise]") {
  Mesh net = grid_network(6, 4, 20, height);
  CHECK(tangent_spread_deg(net) < 0.6);
  CHECK(fit_noise(net) == noise_estimate(net));
  // Every curve bowed up by a smooth bump of 3 % of its length, as a tracked pen errs smoothly along a
  // stroke: each stays smooth, but the curves now leave every vertex out of one plane, by 5.4 degrees
  // where four meet and 4.4 on the border, where three do (the median).
  for (uint32_t e = 0; e < net.edge_slots(); ++e) {
    const uint32_t first = net.edges.point_offset[e], count = net.edges.point_count[e];
    for (uint32_t s = 1; s + 1 < count; ++s)
      net.points.set(first + s, net.points[first + s] + Vec3(0, 0, 0.03 * std::sin(std::numbers::pi * s / (count - 1))));
  }
  CHECK(noise_estimate(net) <= kExactCurveNoise);
  CHECK(tangent_spread_deg(net) == Approx(4.4).margin(0.1));
  CHECK(fit_fairness(Options{}, fit_noise(net)) == Approx(kNoisyFairness));
}
