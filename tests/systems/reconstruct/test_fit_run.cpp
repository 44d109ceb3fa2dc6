// FitRun, the fit spread over frames: however its back-substitutions are spread over calls, it ends on
// LimitFit::solve's points bit for bit, runs exactly the budget per call, and needs no base mesh after it
// starts. The frame shows a new base mesh without limit stencils, builds its fit in two frames and gives
// each frame a share of its solves that shrinks as the base mesh grows. And a fit of noisy curves stops
// where they stop it.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "networks.hpp"
#include "systems/reconstruct/fit.hpp"

using namespace fire;
using namespace fire::reconstruct;
using namespace fire::test;

namespace {

double height(double x, double y) { return 0.5 * std::sin(0.6 * x) * std::cos(0.5 * y) + 0.02 * x * y; }

// The base mesh of a reconstruction of the 4 x 3 grid with `samples` points per curve.
BaseMesh grid_base(const Options& options, uint32_t samples) {
  ReconstructionState state;
  SurfaceMesh surface;
  REQUIRE(reconstruct_update(grid_network(4, 3, samples, height), options, state, surface).ok());
  return state.base();
}

// The fit's topology for a base mesh: its refinement with the last level's adjacency, and limit stencils.
struct Subdivided {
  catmull_clark::Refinement refinement;
  catmull_clark::LimitStencils limit;
};

Subdivided subdivided(const BaseMesh& base, uint32_t levels) {
  const catmull_clark::BaseTopology topology{base.vertex_count(), base.face_offsets, base.face_vertices, base.sharp_edges,
                                             base.border_corners};
  auto refinement = catmull_clark::build_refinement(topology, {int(levels), true});
  REQUIRE(refinement.ok());
  auto limit = catmull_clark::build_limit_stencils(*refinement);
  REQUIRE(limit.ok());
  return {std::move(*refinement), std::move(*limit)};
}

}  // namespace

TEST_CASE("a fit advanced 1, 7 or all back-substitutions at a time ends on solve's points bit for bit",
          "[reconstruct][fit]") {
  // Two Coons steps: four pieces per network edge, so that phase 3 splits the spans too.
  const Options options{Method::Fire, 2, 2, Planarity::LeastSquares};
  const BaseMesh base = grid_base(options, 17);
  const Subdivided topology = subdivided(base, options.levels);
  auto fit = LimitFit::build(topology.refinement, topology.limit, base, FitWeights{});
  REQUIRE(fit.ok());
  std::vector<Vec3> solved;
  const LimitFit::Report whole = fit->solve(base, solved);
  INFO("solve ran " << whole.iterations << " back-substitutions");
  REQUIRE(whole.iterations > 14);
  REQUIRE(solved.size() == base.vertex_count());

  for (uint32_t budget : {1u, 7u, kWholeFit}) {
    INFO("budget " << budget);
    BaseMesh copy = base;
    FitRun run(*fit, copy);
    copy = BaseMesh{};  // read only when the run starts
    CHECK(run.running());
    CHECK_FALSE(run.advance(0));
    uint32_t calls = 1;
    while (!run.advance(budget)) ++calls;
    CHECK_FALSE(run.running());
    // Every call ran its whole budget but the last: no call is left with nothing to do.
    CHECK(calls == (budget == kWholeFit ? 1 : (whole.iterations + budget - 1) / budget));
    CHECK(run.report().iterations == whole.iterations);
    CHECK(run.report().rms == whole.rms);
    REQUIRE(run.points().size() == solved.size());
    CHECK(std::memcmp(run.points().data(), solved.data(), solved.size() * sizeof(Vec3)) == 0);
  }
  CHECK_FALSE(FitRun().running());
}

TEST_CASE("a fit of noisy curves stops once its distance to them stops falling, as close to them as one that runs every solve",
          "[reconstruct][fit]") {
  const Options options{Method::Fire, 1, 2, Planarity::LeastSquares};
  BaseMesh base = grid_base(options, 33);
  // Seeded noise of 1 % of a face's side on every sample but the curves' ends (the network's vertices).
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (uint32_t c = 0; c + 1 < base.curve_offsets.size(); ++c)
    for (uint32_t k = base.curve_offsets[c] + 1; k + 1 < base.curve_offsets[c + 1]; ++k)
      for (int axis = 0; axis < 3; ++axis) base.curve_points[k][axis] += noise(rng);
  const Subdivided topology = subdivided(base, options.levels);
  // The weights the reconstruction gives noisy curves, with and without the stop.
  const FitWeights creeping{.fairness = kNoisyFairness, .targets = Sampling::Linear};
  FitWeights stopping = creeping;
  stopping.stall_rounds = 8;
  stopping.tolerance = 1e-6;
  auto fit_with = [&](const FitWeights& weights, std::vector<Vec3>& points) {
    auto fit = LimitFit::build(topology.refinement, topology.limit, base, weights);
    REQUIRE(fit.ok());
    return fit->solve(base, points);
  };
  std::vector<Vec3> crept, stopped;
  const LimitFit::Report all = fit_with(creeping, crept), early = fit_with(stopping, stopped);
  INFO("every solve: " << all.iterations << " back-substitutions, rms " << all.rms << "; stopped: " << early.iterations
                       << ", rms " << early.rms);
  CHECK(early.iterations * 2 <= all.iterations);
  CHECK(early.rms <= 1.02 * all.rms);
}

TEST_CASE("the frame builds a new fit's rows and factorization in two frames, then shares out its work per frame",
          "[reconstruct][fit][frame]") {
  const Mesh net = grid_network(4, 3, 17, height);
  for (uint32_t work : {1u, 300u, 2000u, Options{}.fit_work_per_frame}) {
    Options options{Method::Fire, 1, 2, Planarity::LeastSquares};
    options.fit_work_per_frame = work;
    ReconstructionState state;
    SurfaceMesh surface;
    REQUIRE(refine_update(net, options, state).ok());
    auto commit = subdivide_update(options, state, surface);
    REQUIRE(commit.ok());
    CHECK(*commit == SurfaceWrite::Provisional);
    const SurfaceMesh provisional = surface;
    uint32_t frames = 0;
    for (SurfaceWrite write = SurfaceWrite::None; write != SurfaceWrite::Settled && frames < 1000; ++frames) {
      auto r = subdivide_update(options, state, surface);
      REQUIRE(r.ok());
      write = *r;
      CHECK((write == SurfaceWrite::Settled || write == SurfaceWrite::None));
    }
    const uint32_t vertices = state.base().vertex_count(), iterations = state.last_update().fit_iterations;
    const uint32_t per_frame = std::max(1u, work / vertices);
    INFO("work " << work << ", " << vertices << " base vertices, " << iterations << " back-substitutions");
    CHECK(frames == 2 + (iterations + per_frame - 1) / per_frame);
    // The commit frame builds no limit stencils: it shows the last level's points of the initial base
    // points, with their quads' normals, a level short of the limit and close to the settled surface.
    const BaseMesh& base = state.base();
    auto refined = catmull_clark::subdivide({{base.positions, base.face_offsets, base.face_vertices}, base.sharp_edges,
                                             base.border_corners},
                                            int(options.levels));
    REQUIRE(refined.ok());
    REQUIRE(provisional.face_vertices == surface.face_vertices);
    REQUIRE(provisional.positions.size() == refined->positions.size());
    CHECK(std::memcmp(provisional.positions.data(), refined->positions.data(),
                      provisional.positions.size() * sizeof(Vec3)) == 0);
    double least_cosine = 1;
    for (size_t v = 0; v < provisional.normals.size(); ++v) {
      CHECK(std::abs(provisional.normals[v].norm() - 1) < 1e-12);
      least_cosine = std::min(least_cosine, provisional.normals[v].dot(refined->limit_normals[v]));
    }
    CHECK(least_cosine > 0.9);
  }
}
