#pragma once
// The FIRE pipeline's last step: base points whose Catmull-Clark limit surface passes through the
// drawn polylines.
//
// The limit position of every level-L vertex is a fixed linear combination of the base points (each
// level's subdivision stencils composed with the last level's limit masks, all from fire_subdivide).
// Along every side lie 2^(D+L) + 1 level-L vertices (D its EdgeSplits::depth: N Coons steps, more for a
// long side; L levels); the fit asks their limit positions to meet the side's polyline, in the
// least-squares sense. Curves alone leave
// each face's interior free (on a regular grid about one bulge mode per face: moving a face's centre
// and its edge midpoints in a way no limit curve along the edges sees), so a small fairness term, the
// squared bi-Laplacian (umbrella operator applied twice) of the base points, picks the smoothest
// surface among those that fit; a tiny ridge towards the initial base points (from the transfinite
// patches) keeps the matrix definite. The normal matrix A^T A + fairness + ridge depends on topology
// alone: it is factored once (sparse LDL^T) and a change of the points costs back-substitutions.
//
// Targets lie on the polylines, read between samples as FitWeights::targets says (phase 2 below finds each
// foot on the chords and reads the polyline at that foot's arc parameter).
// The targets start at equal arc-length steps along each piece of a network edge. A limit curve is not
// parameterized by arc length, so the targets then slide in three phases:
//   1. along whole edges, to the arc-length fractions the fitted limit points have along the fitted
//      curve: the surface keeps its parameterization, and the split points slide too;
//   2. each target becomes the foot point of its fitted limit point on the edge's polyline. Phase 1's
//      fixed point lets the fairness choose the parameterization along each curve; the feet's fixed
//      point minimizes the squared distances of the fitted points to the polylines plus the fairness.
//      Alternating with the solve creeps along the curves, so the last steps are Anderson-mixed. Each
//      foot keeps `min_target_spacing` of the equal step from its neighbours: where a curve bends faster
//      than the surface can follow, the feet would otherwise gather at the bend, and the surface, pinched
//      across the curve there, folds (the rook's K = 2 foot ring: tests/systems/reconstruct/cli_folds.sh).
//      Where it leaves some edges followed closely, phase 2 runs again with less fairness around them,
//      on a second factorization (FitWeights::followed_distance);
//   3. the split points settle on the polyline samples nearest to where phase 2 put them, and each
//      piece slides alone as in phase 1. Where the curves are representable this converges fast (about
//      a factor 6 per solve on smooth data) to a surface through every sample, which phase 2's creep
//      does not reach (test_reconstruct's exact grid). The fit keeps phase 3's solution only if its
//      fitted points lie closer to the polylines (sum of squared distances) than phase 2's.
//   Without phase 2 the split points freeze where phase 1 left them (perf/notes/quality.md,
//   "Reconstruction quality", has the pawn's network_max with and without it).
// Each phase stops when no target moves more than `tolerance` times the base mesh's size.
//
// FitRun is the same fit a few back-substitutions at a time, for the frame (the subdivide system spreads
// it over the frames after a commit): solve() is a FitRun advanced to its end.
#include <memory>
#include <vector>

#include "systems/reconstruct/reconstruct.hpp"
#include "systems/reconstruct/steps.hpp"
#include "systems/catmull_clark/catmull_clark.hpp"

namespace fire::reconstruct {

struct FitWeights {
  // Weight of the bi-Laplacian fairness, relative to the data (both measured by the mean diagonal of
  // their normal matrices); fit_fairness (reconstruct.hpp): Options::fairness, raised for noisy curves.
  double fairness = 1e-3;
  double ridge = 1e-9;  // same scale, towards the initial base points
  // How the targets read a polyline between its samples (fit_targets: smooth for exact curves, linear
  // for noisy ones).
  Sampling targets = Sampling::Smooth;
  // Where the face split leaves thin base quads, the umbrella measures connectivity, not shape: on a
  // sliver it pulls the points across the thin side and the surface folds (the demo dome). There the
  // umbrella of the change from the initial base points (the transfinite patches, which do not fold)
  // costs too, with this weight (same scale as `fairness`) times min((aspect / shape_aspect - 1)^2, 1)
  // per vertex of a quad whose aspect (quad_aspect) exceeds `shape_aspect`. The reconstruction scales
  // it with the curves' noise, as the fairness: the exact curves' fairness for exact curves, this at
  // kNoisyFairness (fit_weights in reconstruct.cpp).
  // perf/notes/quality.md, "Thin quads keep their transfinite shape; the fairness follows the noise",
  // has the sweeps.
  double shape = 0.1;
  double shape_aspect = 3;
  uint32_t slide_iterations = 10;  // solves of phase 1
  uint32_t feet_iterations = 60;   // solves of phase 2
  // Phase 2: each target keeps at least this fraction of the equal arc-length step from its neighbours'
  // targets along its edge.
  double min_target_spacing = 0.3;
  size_t anderson_depth = 10;      // steps mixed in phase 2
  // Where the surface can follow its curves, the fairness that keeps it from folding where it cannot
  // holds it off them (the pawn's collar against the rook's foot ring: perf/notes/quality.md). So after phase 2
  // the base vertices on which only network edges depend whose fitted points and polylines lie within
  // `followed_distance` (times the base mesh's size) of each other get `followed_fairness` on their
  // fairness rows, the fit is factored again, and phase 2 runs on with the solves left but
  // `phase3_iterations`; only if some of those edges lie farther than `close_distance` (the quality
  // table's network_max goal), since a second run costs a factorization and up to twice phase 2's solves.
  // Exact curves the surface can represent come closer; noisy ones are never that close.
  double followed_distance = 2e-4;
  double close_distance = 1e-4;
  double followed_fairness = 0.1;
  uint32_t phase3_iterations = 4;
  uint32_t max_iterations = 110;   // solves in all
  double tolerance = 1e-11;
  // Noisy curves' feet never settle to `tolerance` (the largest move stays near the noise), so phase 2
  // would spend all its solves creeping: with stall_rounds > 0 it stops once the least squared distance of
  // the fitted points to their feet over the last stall_rounds rounds is less than `stall_gain` of itself
  // below the least before them (the sum rises for a round or two now and then: the mixed steps). Set by
  // fit_weights for noisy curves.
  uint32_t stall_rounds = 0;
  double stall_gain = 5e-3;
};

// Per base vertex, the weight of the shape term (FitWeights::shape); all zero where no quad is thin. The
// fit's matrix depends on them as it does on topology, so a changed set needs a new factorization.
std::vector<double> shape_weights(const BaseMesh& base, const FitWeights& weights);

class LimitFit {
 public:
  LimitFit();
  ~LimitFit();
  LimitFit(LimitFit&&) noexcept;
  LimitFit& operator=(LimitFit&&) noexcept;

  // Rows and factorization for this topology (`refinement` of `base`, with last-level adjacency).
  static Result<LimitFit> build(const catmull_clark::Refinement& refinement, const catmull_clark::LimitStencils& limit,
                                const BaseMesh& base, const FitWeights& weights);
  // build in two halves, which the frame runs in two frames (each costs about as much as the other): the
  // rows (the limit stencils of the fitted points, composed down the levels), then the normal matrix and
  // its factorization, for the same `base`. Only a factored fit solves.
  static Result<LimitFit> build_rows(const catmull_clark::Refinement& refinement,
                                     const catmull_clark::LimitStencils& limit, const BaseMesh& base,
                                     const FitWeights& weights);
  Status factor(const BaseMesh& base, const FitWeights& weights);
  struct Report {
    uint32_t iterations = 0;  // solves (back-substitutions)
    double rms = 0;           // rms distance of the fitted limit points to their final targets
  };
  // The fitted base points for base's polylines, from its initial positions.
  Report solve(const BaseMesh& base, std::vector<Vec3>& points) const;

 private:
  friend class FitRun;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// LimitFit::solve spread over calls: the same code, suspended before each back-substitution, so that a
// run advanced to its end gives solve's points bit for bit however its solves were spread.
class FitRun {
 public:
  FitRun() = default;  // no fit: not running
  // Sets up the first targets from base's polylines; runs no back-substitution yet. Reads `base` only
  // here (it may change or go once this returns); `fit` must outlive the run.
  FitRun(const LimitFit& fit, const BaseMesh& base);
  // Runs at most `solves` more back-substitutions, each with the target updates that follow it; true once
  // the fit has finished.
  bool advance(uint32_t solves);
  bool running() const { return steps_.running(); }
  // Once advance has returned true: the fitted base points and how the fit went.
  const std::vector<Vec3>& points() const { return steps_.value().points; }
  const LimitFit::Report& report() const { return steps_.value().report; }

 private:
  struct Fitted {
    std::vector<Vec3> points;
    LimitFit::Report report;
  };
  static Steps<Fitted> fit_steps(const LimitFit::Impl& m, const BaseMesh& base);
  Steps<Fitted> steps_;
};

}  // namespace fire::reconstruct
