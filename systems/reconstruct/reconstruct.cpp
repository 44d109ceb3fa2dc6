#include "systems/reconstruct/reconstruct.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "engine/assert.hpp"
#include "systems/reconstruct/fit.hpp"
#include "systems/catmull_clark/catmull_clark.hpp"

namespace fire::reconstruct {

// The sides of the network's faces as the surface sees them: a network edge, or a chain of edges joined
// through `joined` vertices (joined_vertices), named by its lead, the lowest edge slot in it, and
// running in the lead's stored direction from network vertex `from` to `to`.
struct Sides {
  std::vector<uint8_t> joined;    // per vertex slot
  std::vector<uint32_t> lead;     // per edge slot: the lead of its side (kNone: no face uses it)
  // Per lead slot: the members in order from `from` (edge slot << 1 | 1 where the member runs against
  // the side), and the side's ends.
  std::vector<std::vector<uint32_t>> members;
  std::vector<uint32_t> from, to;
};

struct ReconstructionCache {
  bool built = false;
  Options options;
  // The network's frame and compaction count at the last update: what changed since is recomputed.
  Frame seen = 0;
  uint64_t compactions_seen = 0;
  // Set by the refine stage for the subdivide stage: a new base mesh waits, and whether its topology
  // (hence Catmull-Clark and the fit's factorization) must be rebuilt first.
  bool pending_subdivide = false;
  bool rebuild_topology = false;
  // Per element slot of the network; valid[] says whether the entry holds the element's current result.
  // An entry of `edges` is the split of a side: the chain of network edges led by that slot (sides).
  std::vector<EdgeSplits> edges;
  std::vector<uint8_t> edge_valid;
  std::vector<double> edge_scale;   // short_curve_scale each entry of `edges` was split with (1: none)
  std::vector<std::array<double, 2>> edge_reach;  // how far from each end it was taken straight (straight_reach)
  std::vector<uint8_t> edge_redone;  // recomputed by the current update
  // The chain each valid entry of `edges` was split from (oriented members, Sides::members), and the
  // current sides, rebuilt by every update.
  std::vector<std::vector<uint32_t>> edge_members;
  Sides sides;
  std::vector<FacePatch> faces;
  std::vector<uint8_t> face_valid;
  // Per face slot: the joined sides (FaceSide::joins_next) its entry of `faces` was built with, which
  // follow from its neighbours too (plan_faces).
  std::vector<std::vector<uint8_t>> face_joins;
  BaseMesh base;
  // What depends on the base mesh's topology alone.
  bool have_topology = false;
  std::vector<uint32_t> key_face_offsets, key_face_vertices, key_sharp, key_curve_ends;
  std::vector<uint8_t> key_curve_drawn, key_vertex_drawn, key_border_corners;
  uint32_t key_vertex_count = 0;
  catmull_clark::Refinement refinement;
  // The limit stencils of `refinement`, when have_limit: built by the frame after a commit, with the fit's
  // rows, as the provisional surface is shown without them.
  catmull_clark::LimitStencils limit;
  bool have_limit = false;
  // fit holds the rows of the current topology when fit_rows, and is their factorization only when
  // fit_built; fit_waiting: a new base mesh has been shown and its fit has not started yet. fit_shape: the
  // shape weights it was built with, which depend on the base points (a change of them needs a new
  // factorization too).
  LimitFit fit;
  bool fit_rows = false;
  bool fit_built = false;
  std::vector<double> fit_shape;
  double fit_fairness = 0;  // the fairness it was built with (fit_fairness of the network's noise)
  Sampling fit_targets = Sampling::Smooth;  // and the reading of the polylines (exact or noisy curves)
  double noise = 0;         // noise_estimate of the network at the last refine (fire)
  bool fit_waiting = false;
  // The fit of `base` in progress (fire), between the frame that took the base and the one it ends in.
  // Reset before `base` or `fit` is replaced; declared after `fit`, so destroyed before it.
  FitRun run;
  UpdateStats stats;
  std::vector<Vec3> scratch;
  // The base points of the last surface written as settled: with `base`'s topology, the cage whose limit it is.
  std::vector<Vec3> settled_points;
};

ReconstructionState::ReconstructionState() : cache_(std::make_unique<ReconstructionCache>()) {}
ReconstructionState::~ReconstructionState() = default;
ReconstructionState::ReconstructionState(ReconstructionState&&) noexcept = default;
ReconstructionState& ReconstructionState::operator=(ReconstructionState&&) noexcept = default;
const UpdateStats& ReconstructionState::last_update() const { return cache_->stats; }
const BaseMesh& ReconstructionState::base() const { return cache_->base; }
std::span<const Vec3> ReconstructionState::settled_points() const { return cache_->settled_points; }
bool ReconstructionState::fitting() const { return cache_->fit_waiting || cache_->run.running(); }
uint32_t ReconstructionState::short_curves() const {
  const std::vector<double>& scale = cache_->edge_scale;
  return static_cast<uint32_t>(std::count_if(scale.begin(), scale.end(), [](double s) { return s < 1; }));
}

uint32_t ReconstructionState::joined_vertices() const {
  const std::vector<uint8_t>& joined = cache_->sides.joined;
  return static_cast<uint32_t>(std::count(joined.begin(), joined.end(), uint8_t(1)));
}

namespace {

bool used_by_face(const Mesh& net, uint32_t e) {
  return net.edges.face[e][0] != kNone || net.edges.face[e][1] != kNone;
}

// The mean length of the polylines that bound a face: the scale of noise_estimate.
double mean_curve_length(const Mesh& net) {
  double length = 0;
  uint32_t lines = 0;
  for (EdgeIndex e{0}; e < net.edge_slots(); ++e) {
    if (!net.edge_alive(e) || !used_by_face(net, e)) continue;
    const auto line = net.polyline(e);
    for (size_t i = 1; i < line.size(); ++i) length += (line[i] - line[i - 1]).norm();
    ++lines;
  }
  return lines ? length / lines : 0.0;
}

// The unit direction in which edge e leaves its end v, from v to the polyline's point a fraction
// kTangentReach of its length along: far enough that a hand's jitter does not turn it, near enough to
// be the curve's own direction. A noisy curve (`deviation` > 0, a length) is read from where it leaves the
// pen's rest at v, and at least kCornerReachNoises deviations from there (kPauseNoises).
Vec3 leaving_direction(const Mesh& net, uint32_t e, uint32_t v, double deviation = 0) {
  std::vector<Vec3> line(net.polyline(EdgeIndex{e}).begin(), net.polyline(EdgeIndex{e}).end());
  if (net.edges.vertex[e][0] != v) std::reverse(line.begin(), line.end());
  if (deviation > 0) {
    const std::vector<double> arc = arc_parameters(line);
    size_t rest_end = 0;
    for (size_t i = 1; i < line.size() && arc[i] <= 0.5; ++i)
      if ((line[i] - line.front()).norm() <= kPauseNoises * deviation) rest_end = i;
    line.erase(line.begin(), line.begin() + static_cast<std::ptrdiff_t>(rest_end));
  }
  const std::vector<double> params = arc_parameters(line);
  Vec3 d = sample_polyline(line, params, kTangentReach, Sampling::Linear) - line.front();
  const double reach = kCornerReachNoises * deviation;
  for (size_t i = 1; d.norm() < reach && i < line.size() && params[i] <= 0.5; ++i)
    if ((line[i] - line.front()).norm() >= reach) d = line[i] - line.front();
  return d.normalized();
}

// How many degrees a curve turns passing through a vertex, from the directions its two sides leave it in.
double turn_deg(const Vec3& leaving, const Vec3& other_leaving) {
  return 180.0 - std::acos(std::clamp(leaving.dot(other_leaving), -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

// A border network vertex is a corner of the surface where the border turns by more than
// `threshold_deg`; where it goes straight on it is a smooth point of the border. Noisy curves are read at the
// vertex and past the pen's rest there (kPauseNoises), and the smaller turn counts: noise turns a straight
// border, it does not straighten a corner, and a curve only a few deviations long has no rest to read past.
bool border_corner(const Mesh& net, uint32_t v, double threshold_deg, double deviation) {
  uint32_t border[2], count = 0;
  for (EdgeIndex e : net.vertex_edges(VertexIndex{v}))
    if (used_by_face(net, e) && net.is_border_edge(e)) {
      if (count == 2) return true;  // the border touches itself here
      border[count++] = e;
    }
  if (count != 2) return true;
  auto turn = [&](double rest_deviation) {
    return turn_deg(leaving_direction(net, border[0], v, rest_deviation),
                        leaving_direction(net, border[1], v, rest_deviation));
  };
  return !(std::min(turn(0), deviation > 0 ? turn(deviation) : 180.0) <= threshold_deg);
}


}  // namespace

double quad_aspect(const BaseMesh& base, uint32_t face) {
  const uint32_t first = base.face_offsets[face];
  const Vec3* p[4];
  for (uint32_t k = 0; k < 4; ++k) p[k] = &base.positions[base.face_vertices[first + k]];
  double longest = 0;
  for (uint32_t k = 0; k < 4; ++k) longest = std::max(longest, (*p[(k + 1) % 4] - *p[k]).norm());
  const double area = 0.5 * (*p[2] - *p[0]).cross(*p[3] - *p[1]).norm();
  return area > 0 ? longest * longest / area : std::numeric_limits<double>::infinity();
}

namespace {

// noise_estimate for a network whose mean_curve_length is known.
double noise_estimate(const Mesh& net, double mean_length) {
  std::vector<double> cubed;  // squared third differences of the samples
  for (EdgeIndex e{0}; e < net.edge_slots(); ++e) {
    if (!net.edge_alive(e) || !used_by_face(net, e)) continue;
    const auto line = net.polyline(e);
    // On a few samples the curve's own shape dominates the differences.
    if (line.size() < kNoiseSamples) continue;
    for (size_t i = 3; i < line.size(); ++i)
      cubed.push_back((line[i] - 3 * line[i - 1] + 3 * line[i - 2] - line[i - 3]).squaredNorm());
  }
  if (cubed.empty() || !(mean_length > 0)) return 0;
  auto middle = cubed.begin() + std::ptrdiff_t(cubed.size() / 2);
  std::nth_element(cubed.begin(), middle, cubed.end());
  // Independent noise of deviation s per coordinate: a third difference's squared norm is 20 s^2 times a
  // chi-square of 3 degrees of freedom, whose median is 2.366.
  return std::sqrt(*middle / (20 * 2.366)) / mean_length;
}

}  // namespace

double noise_estimate(const Mesh& net) { return noise_estimate(net, mean_curve_length(net)); }

double tangent_spread_deg(const Mesh& net) {
  // Per vertex: the sum of t t^T over the unit tangents of the curves leaving it, their count, and
  // whether a crease meets there (its curves need not share a plane).
  std::vector<Eigen::Matrix3d> moments(net.vertex_slots(), Eigen::Matrix3d::Zero());
  std::vector<uint32_t> counts(net.vertex_slots(), 0);
  std::vector<bool> crease(net.vertex_slots(), false);
  for (EdgeIndex e{0}; e < net.edge_slots(); ++e) {
    if (!net.edge_alive(e) || !used_by_face(net, e)) continue;
    const auto line = net.polyline(e);
    for (int end = 0; end < 2; ++end) {
      const uint32_t v = net.edges.vertex[e][end];
      if (net.edges.flags[e] & kSharpEdge) crease[v] = true;
      if (line.size() < 3) continue;
      // The derivative at the end of the parabola through its first three samples: a chord's direction
      // is off by half the angle the curve turns over it, which on exact curves is what this measures.
      const size_t n = line.size() - 1;
      const Vec3& p0 = end == 0 ? line[0] : line[n];
      const Vec3& p1 = end == 0 ? line[1] : line[n - 1];
      const Vec3& p2 = end == 0 ? line[2] : line[n - 2];
      const double s1 = (p1 - p0).norm(), s2 = s1 + (p2 - p1).norm();
      if (!(s1 > 0) || !(s2 > s1)) continue;
      const Vec3 d = p0 * (-(s1 + s2) / (s1 * s2)) + p1 * (s2 / (s1 * (s2 - s1))) - p2 * (s1 / (s2 * (s2 - s1)));
      if (!(d.norm() > 0)) continue;
      const Vec3 t = d.normalized();
      moments[v] += t * t.transpose();
      ++counts[v];
    }
  }
  std::vector<double> spread;
  for (VertexIndex v{0}; v < net.vertex_slots(); ++v) {
    if (!net.vertex_alive(v) || crease[v] || counts[v] < 3) continue;
    const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(moments[v], Eigen::EigenvaluesOnly).eigenvalues()(0);
    spread.push_back(std::asin(std::sqrt(std::clamp(smallest / counts[v], 0.0, 1.0))) * 180.0 / std::numbers::pi);
  }
  if (spread.size() < kSpreadVertices) return 0;
  auto middle = spread.begin() + std::ptrdiff_t(spread.size() / 2);
  std::nth_element(spread.begin(), middle, spread.end());
  return *middle;
}

double fit_noise(double noise, double spread_deg) {
  if (noise > kExactCurveNoise || !(spread_deg > kDisagreeingTangentsDeg)) return noise;
  return kExactCurveNoise * std::sqrt(kNoisyFairness / Options{}.fairness);
}

double fit_noise(const Mesh& net) { return fit_noise(noise_estimate(net), tangent_spread_deg(net)); }

double fit_fairness(const Options& options, double noise) {
  if (!options.fairness_from_noise || !(noise > kExactCurveNoise)) return options.fairness;
  const double ratio = noise / kExactCurveNoise;
  const double fairness = std::max(options.fairness, std::min(options.fairness * ratio * ratio, kNoisyFairness));
  if (!(noise > kNoisierCurves)) return fairness;
  const double beyond = noise / kNoisierCurves;
  return std::max(fairness, std::min(kNoisyFairness * beyond * beyond, kNoisiestFairness));
}

Sampling fit_targets(double noise) { return noise > kExactCurveNoise ? Sampling::Linear : Sampling::Smooth; }

double worst_quad_aspect(const BaseMesh& base) {
  double worst = 0;
  for (uint32_t f = 0; f < base.face_count(); ++f)
    if (base.face_offsets[f + 1] - base.face_offsets[f] == 4) worst = std::max(worst, quad_aspect(base, f));
  return worst;
}

Status check_options(const Options& options) {
  if (options.coons_steps < 1 || options.coons_steps > kMaxCoonsSteps)
    return Status::failure("the number of Coons steps must be 1 to " + std::to_string(kMaxCoonsSteps) + ", not " +
                           std::to_string(options.coons_steps));
  if (options.levels < 1 || options.levels > kMaxSurfaceLevels)
    return Status::failure("the subdivision level must be 1 to " + std::to_string(kMaxSurfaceLevels) + ", not " +
                           std::to_string(options.levels));
  if (!(options.fairness >= 0 && options.fairness <= 1))
    return Status::failure("the fairness weight must be 0 to 1, not " + std::to_string(options.fairness));
  if (options.fit_work_per_frame < 1) return Status::failure("the fit's work per frame must be at least 1");
  return Status::success();
}

Status check_reconstruction_input(const Mesh& net, const Options& options) {
  if (Status s = check_options(options); !s) return s;
  if (std::string problem = net.validate(); !problem.empty()) return Status::failure("invalid network: " + problem);
  if (net.face_count() == 0) return Status::failure("the network has no faces");
  for (EdgeIndex e{0}; e < net.edge_slots(); ++e) {
    if (!net.edge_alive(e) || !used_by_face(net, e)) continue;
    auto line = net.polyline(e);
    if (std::all_of(line.begin(), line.end(), [&](const Vec3& p) { return p == line.front(); }))
      return Status::failure("edge " + std::to_string(e) + "'s polyline has zero length");
    for (size_t i = 1; i < line.size(); ++i)
      if (line[i] == line[i - 1])
        return Status::failure("edge " + std::to_string(e) + "'s polyline has coincident consecutive points " +
                               std::to_string(i - 1) + " and " + std::to_string(i));
  }
  for (FaceIndex f{0}; f < net.face_slots(); ++f) {
    if (!net.face_alive(f)) continue;
    auto loop = net.face_loop(f);
    if (options.method == Method::Thesis && loop.size() < 3)
      return Status::failure("face " + std::to_string(f) + " has " + std::to_string(loop.size()) +
                             " edges; the thesis method needs at least 3 (use --method fire)");
    for (size_t i = 0; i < loop.size(); ++i)
      for (size_t j = i + 1; j < loop.size(); ++j) {
        const uint32_t a = net.tail(loop[i]), b = net.tail(loop[j]);
        if (net.vertices.position[a] == net.vertices.position[b])
          return Status::failure("face " + std::to_string(f) + " has coincident corners: vertices " +
                                 std::to_string(a) + " and " + std::to_string(b) + " lie at the same point");
      }
  }
  return Status::success();
}

namespace {

// How much of a curve's departure from its chord the surface takes, given the noise's deviation (a
// length; 0: the curves are exact): none for a curve that reaches less than kChordCurveNoises deviations
// from its ends, all of it from kShortCurveNoises on, linearly between.
double short_curve_scale(std::span<const Vec3> line, double deviation) {
  if (!(deviation > 0)) return 1;
  double reach = 0;
  for (const Vec3& q : line) reach = std::max({reach, (q - line.front()).norm(), (q - line.back()).norm()});
  return std::clamp((reach / deviation - kChordCurveNoises) / (kShortCurveNoises - kChordCurveNoises), 0.0, 1.0);
}

// The polyline the surface takes for a curve of that scale: its chord, plus `scale` of the drawn
// curve's departure from it.
std::vector<Vec3> scaled_polyline(std::span<const Vec3> line, double scale) {
  std::vector<Vec3> out(line.begin(), line.end());
  const std::vector<double> t = arc_parameters(line);
  for (size_t i = 1; i + 1 < out.size(); ++i) {
    const Vec3 chord = line.front() + (line.back() - line.front()) * t[i];
    out[i] = chord + scale * (line[i] - chord);
  }
  return out;
}

// The side `line` with its stretch from its start within `reach` (at most `share` of its length) taken straight
// (kEndStraightNoises): each sample moves toward the point as far along the stretch's mean direction from the
// start as it is along the stretch, fully at the start, not at all at the stretch's end (a smoothstep).
void straighten_start(std::vector<Vec3>& line, double reach, double share) {
  if (!(reach > 0) || line.size() < 3) return;
  double length = 0;
  for (size_t i = 1; i < line.size(); ++i) length += (line[i] - line[i - 1]).norm();
  reach = std::min(reach, share * length);
  size_t end = 1;
  while (end + 1 < line.size() && (line[end] - line[0]).norm() < reach) ++end;
  if (end < 2) return;
  std::vector<double> arc(end + 1, 0.0);
  Eigen::Matrix3d moments = Eigen::Matrix3d::Zero();
  for (size_t i = 1; i <= end; ++i) {
    arc[i] = arc[i - 1] + (line[i] - line[i - 1]).norm();
    moments += (line[i] - line[0]) * (line[i] - line[0]).transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(moments);
  Vec3 direction = solver.eigenvectors().col(2);
  if (direction.dot(line[end] - line[0]) < 0) direction = -direction;
  const double along = direction.dot(line[end] - line[0]);
  for (size_t i = 1; i < end; ++i) {
    const double t = arc[i] / arc[end], weight = 1 - t * t * (3 - 2 * t);
    line[i] += weight * (line[0] + direction * (along * t) - line[i]);
  }
}

// How far from a vertex of that valence a noisy side is taken straight (kEndStraightNoises), and the most of
// the side's length that may be.
std::pair<double, double> straight_reach(uint32_t valence, double deviation) {
  const double crowded = std::max(1.0, double(valence) / 4);
  return {kEndStraightNoises * deviation * crowded, kEndStraightShare * std::min(2.0, crowded)};
}

// With noisy curves, an interior network vertex where just two curves meet is left out of the base mesh:
// its two edges become one side of both its faces. Kept, it would be a base vertex of valence 2, and a
// fit stiff enough for the noise pins that degenerate Catmull-Clark vertex to the turn the curve takes
// there and pleats the two quads at it (the rook's battlement notches, perf/notes/quality.md). Exact curves
// keep it: the fit follows them closely, and a turn inside one side would fold it instead. Never where
// a face would keep fewer than two corners, nor between edges of different sharpness.
std::vector<uint8_t> joined_vertices(const Mesh& net, bool noisy) {
  std::vector<uint8_t> joined(net.vertex_slots(), 0);
  if (!noisy) return joined;
  std::vector<uint32_t> used(net.vertex_slots(), 0), first(net.vertex_slots(), kNone);
  std::vector<uint8_t> candidate(net.vertex_slots(), 1);
  for (EdgeIndex e{0}; e < net.edge_slots(); ++e) {
    if (!net.edge_alive(e) || !used_by_face(net, e)) continue;
    const uint32_t a = net.edges.vertex[e][0], b = net.edges.vertex[e][1];
    const bool interior = !net.is_border_edge(e) && net.edges.face[e][0] != net.edges.face[e][1] && a != b;
    for (uint32_t v : {a, b}) {
      ++used[v];
      if (!interior) candidate[v] = 0;
      if (first[v] == kNone) {
        first[v] = e;
      } else if (used[v] == 2) {
        const uint32_t g = first[v];
        const uint32_t far_e = a == v ? b : a;
        const uint32_t far_g = net.edges.vertex[g][0] == v ? net.edges.vertex[g][1] : net.edges.vertex[g][0];
        const bool same_sharpness = ((net.edges.flags[e] ^ net.edges.flags[g]) & kSharpEdge) == 0;
        if (g == e || far_e == far_g || !same_sharpness) candidate[v] = 0;
      }
    }
  }
  for (VertexIndex v{0}; v < net.vertex_slots(); ++v) joined[v] = net.vertex_alive(v) && used[v] == 2 && candidate[v];
  for (FaceIndex f{0}; f < net.face_slots(); ++f) {
    if (!net.face_alive(f)) continue;
    const auto loop = net.face_loop(f);
    const auto kept = std::count_if(loop.begin(), loop.end(), [&](OrientedEdge oe) { return !joined[net.tail(oe)]; });
    if (kept < 2)
      for (OrientedEdge oe : loop) joined[net.tail(oe)] = 0;
  }
  return joined;
}

// The sides of the faces, from the joined vertices: each edge a face uses walked forwards and back
// through joined vertices to the ends of its chain.
void build_sides(const Mesh& net, bool noisy, Sides& sides) {
  sides.joined = joined_vertices(net, noisy);
  sides.lead.assign(net.edge_slots(), kNone);
  sides.members.resize(net.edge_slots());
  sides.from.assign(net.edge_slots(), kNone);
  sides.to.assign(net.edge_slots(), kNone);
  // The other edge at a joined vertex.
  std::vector<uint32_t> pair(2 * size_t(net.vertex_slots()), kNone);
  for (EdgeIndex e{0}; e < net.edge_slots(); ++e) {
    if (!net.edge_alive(e) || !used_by_face(net, e)) continue;
    for (uint32_t v : net.edges.vertex[e])
      if (sides.joined[v]) pair[2 * size_t(v) + (pair[2 * size_t(v)] == kNone ? 0 : 1)] = e;
  }
  auto across = [&](uint32_t v, uint32_t e) { return pair[2 * size_t(v)] == e ? pair[2 * size_t(v) + 1] : pair[2 * size_t(v)]; };
  auto far_end = [&](uint32_t e, uint32_t v) { return net.edges.vertex[e][0] == v ? net.edges.vertex[e][1] : net.edges.vertex[e][0]; };
  std::vector<uint32_t> back;
  for (EdgeIndex e{0}; e < net.edge_slots(); ++e) {
    std::vector<uint32_t>& members = sides.members[e];
    members.clear();
    if (!net.edge_alive(e) || !used_by_face(net, e) || sides.lead[e] != kNone) continue;
    // Backwards from the lead's first vertex, then forwards from its second; joined_vertices leaves no
    // chain closed on itself (its faces would keep no corner).
    back.clear();
    uint32_t v = net.edges.vertex[e][0];
    for (uint32_t g = e; sides.joined[v];) {
      g = across(v, g);
      FIRE_ASSERT(g != e, "a chain of joined vertices closed on itself");
      const uint32_t next = far_end(g, v);
      back.push_back(g << 1 | (net.edges.vertex[g][1] == v ? 0u : 1u));
      v = next;
    }
    sides.from[e] = v;
    members.assign(back.rbegin(), back.rend());
    members.push_back(e << 1);
    v = net.edges.vertex[e][1];
    for (uint32_t g = e; sides.joined[v];) {
      g = across(v, g);
      members.push_back(g << 1 | (net.edges.vertex[g][0] == v ? 0u : 1u));
      v = far_end(g, v);
    }
    sides.to[e] = v;
    for (uint32_t m : members) sides.lead[m >> 1] = e;
  }
}

// The sides of each live face slot in loop order, from its first corner that is not joined; `splits`
// points at the cache's entry for the side, filled in later.
std::vector<std::vector<FaceSide>> face_sides(const Mesh& net, const Sides& sides, ReconstructionCache& c) {
  // Each side's drawn length and segments, once for both its faces.
  std::vector<double> length(net.edge_slots(), 0.0);
  std::vector<size_t> segments(net.edge_slots(), 0);
  for (EdgeIndex lead{0}; lead < net.edge_slots(); ++lead)
    for (uint32_t m : sides.members[lead]) {
      length[lead] += polyline_length(net.polyline(EdgeIndex{m >> 1}));
      segments[lead] += net.edges.point_count[m >> 1] - 1;
    }
  std::vector<std::vector<FaceSide>> all(net.face_slots());
  for (FaceIndex f{0}; f < net.face_slots(); ++f) {
    if (!net.face_alive(f)) continue;
    auto loop = net.face_loop(f);
    const size_t n = loop.size();
    size_t start = 0;
    while (sides.joined[net.tail(loop[start])]) ++start;
    for (size_t i = 0; i < n; ++i) {
      const OrientedEdge oe = loop[(start + i) % n];
      if (sides.joined[net.tail(oe)]) continue;
      const uint32_t lead = sides.lead[edge_of(oe)];
      const std::vector<uint32_t>& members = sides.members[lead];
      const auto member = std::find_if(members.begin(), members.end(), [&](uint32_t m) { return (m >> 1) == edge_of(oe); });
      all[f].push_back({&c.edges[lead], lead, sides.from[lead], sides.to[lead], is_reversed(oe) != ((*member & 1) != 0),
                        length[lead], segments[lead]});
    }
  }
  return all;
}

// The network edge of `side` that touches its end `v`.
uint32_t end_member(const Sides& sides, const FaceSide& side, uint32_t v) {
  const std::vector<uint32_t>& members = sides.members[side.network_edge];
  return (v == side.to ? members.back() : members.front()) >> 1;
}

// Whether side k of a face is half of a side joined at one of its ends.
bool joined_half(const std::vector<FaceSide>& face, size_t k) {
  return face[k].joins_next || face[(k + face.size() - 1) % face.size()].joins_next;
}

// fire: which sides of each face run straight on into the next (FaceSide::joins_next). Two sides join
// where the loop turns by at most `straight_turn` degrees and neither is more than kLongSideRatio times the
// other, the straightest corners first, each side in one pair at most, while the face keeps more than
// four sides: four sides already split into a grid of quads (a disc bounded by four arcs stays so).
// A joined pair stays only where each of its halves is a half in every face that uses it: a half is split
// one step less than the faces' Coons steps, and a face that did not join it would have to split it.
void plan_faces(const Mesh& net, const Options& options, const Sides& sides, double straight_turn,
                std::vector<std::vector<FaceSide>>& all) {
  if (options.method != Method::Fire) return;
  std::vector<std::pair<double, uint32_t>> corners;  // (turn, the side the corner ends)
  for (std::vector<FaceSide>& face : all) {
    const uint32_t n = static_cast<uint32_t>(face.size());
    if (n <= 4) continue;
    corners.clear();
    for (uint32_t k = 0; k < n; ++k) {
      const FaceSide& in = face[k];
      const FaceSide& out = face[(k + 1) % n];
      if (in.from == in.to || out.from == out.to || in.network_edge == out.network_edge) continue;
      if (std::max(in.length, out.length) > kLongSideRatio * std::min(in.length, out.length)) continue;
      const uint32_t v = in.reversed ? in.from : in.to;
      const double turn = turn_deg(leaving_direction(net, end_member(sides, in, v), v),
                                       leaving_direction(net, end_member(sides, out, v), v));
      if (turn <= straight_turn) corners.emplace_back(turn, k);
    }
    std::sort(corners.begin(), corners.end());
    uint32_t kept = n;
    for (const auto& [turn, k] : corners) {
      if (kept <= 4 || face[k].joins_next || joined_half(face, k) || face[(k + 1) % n].joins_next) continue;
      face[k].joins_next = true;
      --kept;
    }
  }
  std::vector<uint32_t> uses(net.edge_slots()), halves(net.edge_slots());
  for (bool dropped = true; dropped;) {
    dropped = false;
    std::fill(uses.begin(), uses.end(), 0u);
    std::fill(halves.begin(), halves.end(), 0u);
    for (const std::vector<FaceSide>& face : all)
      for (size_t k = 0; k < face.size(); ++k) {
        ++uses[face[k].network_edge];
        if (joined_half(face, k)) ++halves[face[k].network_edge];
      }
    for (std::vector<FaceSide>& face : all)
      for (size_t k = 0; k < face.size(); ++k) {
        const uint32_t a = face[k].network_edge, b = face[(k + 1) % face.size()].network_edge;
        if (face[k].joins_next && (halves[a] != uses[a] || halves[b] != uses[b])) {
          face[k].joins_next = false;
          dropped = true;
        }
      }
  }
}

// How many times each side is split (EdgeSplits::depth), by its lead edge: the Coons steps (one less for
// the halves of a joined side), and for FIRE one more for each doubling the side needs to come within
// kLongSideRatio of the mean side of every face it borders (at most kMaxSideDoublings).
std::vector<uint32_t> side_depths(const Mesh& net, const Options& options, const std::vector<std::vector<FaceSide>>& all) {
  std::vector<uint32_t> depth(net.edge_slots(), options.coons_steps);
  if (options.method != Method::Fire) return depth;
  for (const std::vector<FaceSide>& face : all)
    for (size_t k = 0; k < face.size(); ++k)
      if (joined_half(face, k)) depth[face[k].network_edge] = options.coons_steps - 1;
  for (const std::vector<FaceSide>& face : all) {
    if (face.empty()) continue;
    double total = 0;
    for (const FaceSide& side : face) total += side.length;
    const double mean = total / double(face.size());
    for (size_t k = 0; k < face.size(); ++k) {
      uint32_t doublings = 0;
      while (doublings < kMaxSideDoublings && face[k].length > kLongSideRatio * double(1u << doublings) * mean) ++doublings;
      const uint32_t e = face[k].network_edge;
      depth[e] = std::max(depth[e], (joined_half(face, k) ? options.coons_steps - 1 : options.coons_steps) + doublings);
    }
  }
  return depth;
}

// The per-edge and per-face stages, for the elements whose tags say they may have changed, or (edges)
// whose short-curve scale did.
void update_elements(const Mesh& net, const Options& options, ReconstructionCache& c, bool everything,
                     double deviation, double straight_turn) {
  c.edges.resize(net.edge_slots());
  c.edge_valid.resize(net.edge_slots(), 0);
  c.edge_scale.resize(net.edge_slots(), 1.0);
  c.edge_reach.resize(net.edge_slots(), {0, 0});
  c.edge_members.resize(net.edge_slots());
  c.edge_redone.assign(net.edge_slots(), 0);
  c.faces.resize(net.face_slots());
  c.face_valid.resize(net.face_slots(), 0);
  c.stats = {};
  c.face_joins.resize(net.face_slots());
  build_sides(net, options.method == Method::Fire && deviation > 0, c.sides);
  const Sides& sides = c.sides;
  std::vector<std::vector<FaceSide>> all_sides = face_sides(net, sides, c);
  plan_faces(net, options, sides, straight_turn, all_sides);
  const std::vector<uint32_t> depth = side_depths(net, options, all_sides);
  std::vector<Vec3> line, straight;
  for (EdgeIndex e{0}; e < net.edge_slots(); ++e) {
    const std::vector<uint32_t>& members = sides.members[e];
    if (members.empty()) {
      c.edges[e] = {};
      c.edge_valid[e] = 0;
      c.edge_scale[e] = 1;
      c.edge_reach[e] = {0, 0};
      c.edge_members[e].clear();
      continue;
    }
    // The side as drawn (a lone edge, the common case, read in place); a short noisy side is taken nearer
    // its chord as a whole.
    std::span<const Vec3> side = net.polyline(e);
    if (members.size() > 1) {
      line.clear();
      for (uint32_t m : members) {
        const auto drawn = net.polyline(EdgeIndex{m >> 1});
        const size_t at = line.size();
        line.insert(line.end(), drawn.begin(), drawn.end());
        if (m & 1) std::reverse(line.begin() + std::ptrdiff_t(at), line.end());
        if (at > 0) line.erase(line.begin() + std::ptrdiff_t(at));  // the joined vertex, once
      }
      side = line;
    }
    // A noisy side leaves its end vertices straight; how far depends on their valence, which the side's own
    // stamps do not see change.
    std::array<double, 2> reach{0, 0};
    if (deviation > 0) {
      const uint32_t first = members.front(), last = members.back();
      const uint32_t ends[2] = {net.edges.vertex[first >> 1][first & 1], net.edges.vertex[last >> 1][(last & 1) ^ 1]};
      straight.assign(side.begin(), side.end());
      for (int k = 0; k < 2; ++k) {
        const auto [distance, share] = straight_reach(net.valence(VertexIndex{ends[k]}), deviation);
        reach[k] = distance;
        straighten_start(straight, distance, share);
        std::reverse(straight.begin(), straight.end());  // the other end next, then back in order
      }
      side = straight;
    }
    const double scale = short_curve_scale(side, deviation);
    const bool fresh = everything || !c.edge_valid[e];
    const bool rejoined = !fresh && c.edge_members[e] != members;
    bool stamped = false;
    for (uint32_t m : members) stamped = stamped || net.edges.changes.changed_since(m >> 1, c.seen);
    const bool rescaled = scale != c.edge_scale[e] || reach != c.edge_reach[e];
    const bool resplit = !fresh && depth[e] != c.edges[e].depth;
    if (!fresh && !stamped && !rejoined && !rescaled && !resplit) continue;
    if (!fresh && !stamped) ++(rejoined ? c.stats.edges_rejoined : rescaled ? c.stats.edges_rescaled : c.stats.edges_resplit);
    c.edges[e] = scale < 1 ? split_network_edge(scaled_polyline(side, scale), depth[e])
                           : split_network_edge(side, depth[e]);
    c.edge_valid[e] = 1;
    c.edge_scale[e] = scale;
    c.edge_reach[e] = reach;
    c.edge_members[e] = members;
    for (uint32_t m : members) c.edge_redone[m >> 1] = 1;
    ++c.stats.edges_recomputed;
  }
  const FaceSettings settings{options.method, options.coons_steps, options.planarity};
  std::vector<uint8_t> joins;
  for (FaceIndex f{0}; f < net.face_slots(); ++f) {
    if (!net.face_alive(f)) {
      c.faces[f] = {};
      c.face_valid[f] = 0;
      continue;
    }
    joins.clear();
    for (const FaceSide& side : all_sides[f]) joins.push_back(side.joins_next ? 1 : 0);
    bool stale = everything || !c.face_valid[f] || net.faces.changes.changed_since(f, c.seen) || c.face_joins[f] != joins;
    for (OrientedEdge oe : net.face_loop(f)) stale = stale || c.edge_redone[edge_of(oe)];
    if (!stale) continue;
    c.faces[f] = build_face_patch(all_sides[f], settings);
    c.face_valid[f] = 1;
    c.face_joins[f] = joins;
    ++c.stats.faces_recomputed;
  }
}

// Global numbering, in slot order: network vertices used by faces, then the split points of each edge,
// then the vertices made inside each face. fire: border vertices turning by more than `corner_turn`
// degrees are corners, read on noisy curves of noise `deviation` (a length) past the pen's rests.
BaseMesh assemble(const Mesh& net, const Options& options, const ReconstructionCache& c, double corner_turn,
                  double deviation) {
  BaseMesh base;
  std::vector<uint32_t> vertex_id(net.vertex_slots(), kNone), edge_first(net.edge_slots(), kNone),
      face_first(net.face_slots(), kNone);
  const Sides& sides = c.sides;
  for (FaceIndex f{0}; f < net.face_slots(); ++f)
    if (net.face_alive(f))
      for (OrientedEdge oe : net.face_loop(f))
        if (!sides.joined[net.tail(oe)]) vertex_id[net.tail(oe)] = 0;
  for (VertexIndex v{0}; v < net.vertex_slots(); ++v)
    if (vertex_id[v] != kNone) {
      vertex_id[v] = base.vertex_count();
      base.positions.push_back(net.vertices.position[v]);
      base.vertex_drawn.push_back(1);
      if (options.method == Method::Fire)
        base.border_corners.push_back(border_corner(net, v, corner_turn, deviation) ? 1 : 0);
    }
  for (EdgeIndex e{0}; e < net.edge_slots(); ++e) {
    if (!c.edge_valid[e]) continue;
    edge_first[e] = base.vertex_count();
    for (uint32_t i = 1; i < c.edges[e].leaf_count(); ++i) {
      base.positions.push_back(c.edges[e].leaf(i).front());
      base.vertex_drawn.push_back(1);
    }
  }
  for (FaceIndex f{0}; f < net.face_slots(); ++f) {
    if (!net.face_alive(f)) continue;
    face_first[f] = base.vertex_count();
    base.positions.insert(base.positions.end(), c.faces[f].interior.begin(), c.faces[f].interior.end());
    base.vertex_drawn.resize(base.positions.size(), 0);
  }
  auto id = [&](const VertexRef& r, uint32_t face) -> uint32_t {
    switch (r.kind) {
      case RefKind::NetworkVertex: return vertex_id[r.index];
      case RefKind::EdgePoint: return edge_first[r.index] + r.sub - 1;
      case RefKind::Interior: return face_first[face] + r.index;
    }
    return kNone;
  };
  for (FaceIndex f{0}; f < net.face_slots(); ++f) {
    if (!net.face_alive(f)) continue;
    const FacePatch& p = c.faces[f];
    for (uint32_t k = 0; k < p.face_count(); ++k) {
      for (uint32_t i = p.face_offsets[k]; i < p.face_offsets[k + 1]; ++i) base.face_vertices.push_back(id(p.face_vertices[i], f));
      base.face_offsets.push_back(static_cast<uint32_t>(base.face_vertices.size()));
      base.face_source.push_back(f);
    }
  }
  // Drawn curves: the pieces of each side, between its ends and split points.
  for (EdgeIndex e{0}; e < net.edge_slots(); ++e) {
    if (!c.edge_valid[e]) continue;
    const bool sharp = (net.edges.flags[e] & kSharpEdge) != 0;
    const uint32_t pieces = c.edges[e].leaf_count();
    for (uint32_t i = 0; i < pieces; ++i) {
      const uint32_t a = i == 0 ? vertex_id[sides.from[e]] : edge_first[e] + i - 1;
      const uint32_t b = i + 1 == pieces ? vertex_id[sides.to[e]] : edge_first[e] + i;
      base.curve_ends.push_back(a);
      base.curve_ends.push_back(b);
      auto leaf = c.edges[e].leaf(i);
      base.curve_points.insert(base.curve_points.end(), leaf.begin(), leaf.end());
      base.curve_offsets.push_back(static_cast<uint32_t>(base.curve_points.size()));
      base.curve_drawn.push_back(1);
      if (sharp) {
        base.sharp_edges.push_back(a);
        base.sharp_edges.push_back(b);
      }
    }
    base.side_curve_offsets.push_back(base.curve_count());
  }
  for (FaceIndex f{0}; f < net.face_slots(); ++f) {
    if (!net.face_alive(f)) continue;
    const FacePatch& p = c.faces[f];
    for (uint32_t k = 0; k < p.curve_count(); ++k) {
      base.curve_ends.push_back(id(p.curve_ends[2 * k], f));
      base.curve_ends.push_back(id(p.curve_ends[2 * k + 1], f));
      auto line = p.curve(k);
      base.curve_points.insert(base.curve_points.end(), line.begin(), line.end());
      base.curve_offsets.push_back(static_cast<uint32_t>(base.curve_points.size()));
      base.curve_drawn.push_back(0);
    }
  }
  if (options.method == Method::Fire) base.border_corners.resize(base.vertex_count(), 0);
  return base;
}

bool same_topology(const ReconstructionCache& c, const BaseMesh& b) {
  return c.have_topology && c.key_vertex_count == b.vertex_count() && c.key_face_offsets == b.face_offsets &&
         c.key_face_vertices == b.face_vertices && c.key_sharp == b.sharp_edges && c.key_border_corners == b.border_corners && c.key_curve_ends == b.curve_ends &&
         c.key_curve_drawn == b.curve_drawn && c.key_vertex_drawn == b.vertex_drawn;
}

// Catmull-Clark topology of the base mesh; its limit stencils are left to ensure_limit, the fit's rows and
// factorization (fire) to build_fit, the two frames after in the live frame.
Status rebuild_topology(const Options& options, ReconstructionCache& c) {
  const BaseMesh& b = c.base;
  c.have_topology = false;
  c.have_limit = false;
  c.fit_rows = false;
  c.fit_built = false;
  catmull_clark::BaseTopology topology{b.vertex_count(), b.face_offsets, b.face_vertices, b.sharp_edges, b.border_corners};
  auto refinement = catmull_clark::build_refinement(topology, {static_cast<int>(options.levels), true});
  if (!refinement) return Status::failure("the base mesh cannot be subdivided: " + refinement.error());
  c.refinement = std::move(*refinement);
  c.key_vertex_count = b.vertex_count();
  c.key_face_offsets = b.face_offsets;
  c.key_face_vertices = b.face_vertices;
  c.key_sharp = b.sharp_edges;
  c.key_border_corners = b.border_corners;
  c.key_curve_ends = b.curve_ends;
  c.key_curve_drawn = b.curve_drawn;
  c.key_vertex_drawn = b.vertex_drawn;
  c.have_topology = true;
  return Status::success();
}

Status ensure_limit(ReconstructionCache& c) {
  if (c.have_limit) return Status::success();
  if (auto s = catmull_clark::build_limit_stencils(c.refinement, c.limit); !s)
    return Status::failure("internal error: " + s.error);
  c.have_limit = true;
  return Status::success();
}

// The deviation of the curves' noise that short_curve_scale measures reaches in, a length: the larger of
// the fit's noise and the sideways step of a curve turned by the tangent spread over kTangentReach of its
// length (what correlated noise shows, whose deviation fit_noise does not measure). 0 for exact curves and
// an explicit fairness: no curve is short.
double curve_noise_deviation(const Options& options, double noise, double spread_deg, double mean_length) {
  if (!options.fairness_from_noise || !(noise > kExactCurveNoise)) return 0;
  const double turned = std::sin(spread_deg * std::numbers::pi / 180) * kTangentReach;
  return std::max(noise, turned) * mean_length;
}

// The shape term comes with the noise too: noisy hand-drawn curves keep their thin quads' transfinite
// shape. Exact curves are followed as drawn, so for them it weighs only as much as their fairness: the
// full weight would cost the rook's exact network its rms goal, none lets a sliver's quads fold (the
// rook K = 2 network's face 186; perf/notes/quality.md). An explicit --fairness has none.
FitWeights fit_weights(const Options& options, double noise) {
  FitWeights weights;
  weights.fairness = fit_fairness(options, noise);
  weights.targets = fit_targets(noise);
  // Noisy curves: the fit stops where its points' distance to the curves has stopped falling and where
  // they move by a millionth of the object, both far below the noise (perf/notes/frame.md, "A fit that
  // stops where noisy curves stop it").
  if (weights.targets == Sampling::Linear) {
    weights.stall_rounds = 8;
    weights.tolerance = 1e-6;
  }
  if (!options.fairness_from_noise || !(kNoisyFairness > options.fairness)) {
    weights.shape = 0;
    return weights;
  }
  const double noisy = (weights.fairness - options.fairness) / (kNoisyFairness - options.fairness);
  weights.shape = std::max(weights.shape * std::clamp(noisy, 0.0, 1.0), options.fairness);
  return weights;
}

// The fit's rows for the topology, if it has none yet, and then, or in the next call unless `whole`, their
// factorization.
Status build_fit(const Options& options, ReconstructionCache& c, bool whole) {
  const FitWeights weights = fit_weights(options, c.noise);
  c.run = {};
  if (!c.fit_rows) {
    if (Status s = ensure_limit(c); !s) return s;
    auto fit = LimitFit::build_rows(c.refinement, c.limit, c.base, weights);
    if (!fit) return Status::failure(fit.error());
    c.fit = std::move(*fit);
    c.fit_rows = true;
    if (!whole) return Status::success();
  }
  if (Status factored = c.fit.factor(c.base, weights); !factored) return factored;
  c.fit_built = true;
  c.fit_shape = shape_weights(c.base, weights);
  c.fit_fairness = weights.fairness;
  c.fit_targets = weights.targets;
  return Status::success();
}

// Per-element stage and base mesh. `assembled`: the base mesh may differ from the last update's.
Result<Refined> run_refine(const Mesh& net, const Options& options, ReconstructionCache& c) {
  // Cached results name slots; after a compaction they would name the wrong ones.
  const bool everything =
      !c.built || !(c.options == options) || net.last_compaction().count != c.compactions_seen;
  // An unchanged network passed the check when it was last built (a failed one empties the cache).
  if (!everything && !c.pending_subdivide && !net.written_after(c.seen)) {
    c.stats = {};
    return Refined::Unchanged;
  }
  if (auto s = check_reconstruction_input(net, options); !s) return Result<Refined>::failure(s.error);
  c.built = false;
  c.options = options;
  c.run = {};  // a fit of the previous base mesh is abandoned; subdivide starts one from the new
  // Noise turns a curve's first stretch too: a border turn within the spread of the curves' directions
  // where they meet is the noise's, not a corner (the pawn's border at 4 % correlated noise).
  const double spread = options.method == Method::Fire ? tangent_spread_deg(net) : 0.0;
  FitWeights weights;
  double deviation = 0;
  if (options.method == Method::Fire) {
    const double mean_length = mean_curve_length(net);
    c.noise = options.fairness_from_noise ? fit_noise(noise_estimate(net, mean_length), spread) : 0;
    weights = fit_weights(options, c.noise);
    deviation = curve_noise_deviation(options, c.noise, spread, mean_length);
  }
  update_elements(net, options, c, everything, deviation, kStraightCornerTurn - spread);
  c.base = assemble(net, options, c, kBorderCornerTurnDeg + spread, deviation);
  c.rebuild_topology = c.rebuild_topology || everything || !same_topology(c, c.base);
  if (options.method == Method::Fire && c.fit_built &&
      (weights.fairness != c.fit_fairness || weights.targets != c.fit_targets ||
       shape_weights(c.base, weights) != c.fit_shape))
    c.fit_built = false;
  c.pending_subdivide = true;
  c.seen = net.frame();
  c.compactions_seen = net.last_compaction().count;
  c.built = true;
  return Refined::Assembled;
}

Status evaluate_surface(ReconstructionCache& c, std::span<const Vec3> base_points, SurfaceMesh& surface) {
  if (Status s = ensure_limit(c); !s) return s;
  std::vector<Vec3> last_level;
  catmull_clark::evaluate(c.refinement, base_points, last_level, c.scratch);
  SurfaceMesh out;
  catmull_clark::evaluate_limit(c.limit, last_level, out.positions, out.normals);
  out.face_offsets = c.refinement.last().face_offsets;
  out.face_vertices = c.refinement.last().face_vertices;
  surface = std::move(out);
  return Status::success();
}

// The provisional surface: the last level's points themselves, a level short of the limit, with the
// normals of their quads, so the commit frame builds no limit stencils (perf/notes/frame.md, "The commit
// frame without limit stencils"). The settled surface replaces it a few frames later.
void evaluate_provisional(ReconstructionCache& c, SurfaceMesh& surface) {
  const catmull_clark::Level& last = c.refinement.last();
  SurfaceMesh out;
  catmull_clark::evaluate(c.refinement, c.base.positions, out.positions, c.scratch);
  out.normals.assign(out.positions.size(), Vec3::Zero());
  for (uint32_t f = 0; f + 1 < last.face_offsets.size(); ++f) {
    const uint32_t* q = last.face_vertices.data() + last.face_offsets[f];
    const Vec3 n = (out.positions[q[2]] - out.positions[q[0]]).cross(out.positions[q[3]] - out.positions[q[1]]);
    for (int k = 0; k < 4; ++k) out.normals[q[k]] += n;
  }
  for (Vec3& n : out.normals) {
    const double length = n.norm();
    n = length > 0.0 ? Vec3(n / length) : Vec3::Zero();
  }
  out.face_offsets = last.face_offsets;
  out.face_vertices = last.face_vertices;
  surface = std::move(out);
}

// The commit frame shows the provisional surface, the next two build the fit: 4 frames are left for the
// solves of a base mesh of up to this many vertices to settle within 6 frames (reconstruct.hpp).
static_assert(4 * (Options{}.fit_work_per_frame / 280) >= FitWeights{}.max_iterations);

Result<SurfaceWrite> run_subdivide(const Options& options, ReconstructionCache& c, SurfaceMesh& surface) {
  const bool whole = options.fit_work_per_frame == kWholeFit;
  const uint32_t fit_solves =
      whole ? kWholeFit : std::max<uint32_t>(1, options.fit_work_per_frame / std::max<uint32_t>(1, c.base.vertex_count()));
  if (c.pending_subdivide) {
    if (c.rebuild_topology) {
      if (auto s = rebuild_topology(options, c); !s) return Result<SurfaceWrite>::failure(s.error);
      c.stats.topology_rebuilt = true;
      c.rebuild_topology = false;
    }
    c.pending_subdivide = false;
    if (options.method == Method::Thesis) {
      if (Status s = evaluate_surface(c, c.base.positions, surface); !s) return Result<SurfaceWrite>::failure(s.error);
      c.settled_points = c.base.positions;
      return SurfaceWrite::Settled;
    }
    // The fit starts from the base mesh's points, the transfinite patches': their surface is shown until
    // it ends. In the frame, that is all this call does: the topology was its work.
    c.fit_waiting = true;
    if (!whole) {
      evaluate_provisional(c, surface);
      return SurfaceWrite::Provisional;
    }
  }
  if (c.fit_waiting) {
    // A new fit's rows and its factorization are each the whole of their frame's work; with the old
    // factorization the solves start at once.
    const bool factorized = !c.fit_built;
    if (factorized) {
      if (auto s = build_fit(options, c, whole); !s) return Result<SurfaceWrite>::failure(s.error);
      if (!c.fit_built) return SurfaceWrite::None;
    }
    c.run = FitRun(c.fit, c.base);
    c.fit_waiting = false;
    if (factorized && !whole) return SurfaceWrite::None;
  }
  if (!c.run.running() || !c.run.advance(fit_solves)) return SurfaceWrite::None;
  // Only the provisional surface and the settled one are written, not the fit's iterates between: each
  // write costs an evaluation and moves every vertex (a whole upload), and the iterates are no better a
  // preview (phase 2 creeps, and the fit keeps phase 2's or phase 3's solution only at its end).
  c.stats.fit_iterations = c.run.report().iterations;
  c.stats.fit_rms = c.run.report().rms;
  if (Status s = evaluate_surface(c, c.run.points(), surface); !s) return Result<SurfaceWrite>::failure(s.error);
  c.settled_points = c.run.points();
  c.run = {};
  return SurfaceWrite::Settled;
}

}  // namespace

Result<Refined> refine_update(const Mesh& net, const Options& options, ReconstructionState& state) {
  Result<Refined> r = run_refine(net, options, state.cache());
  if (!r) state.cache() = ReconstructionCache{};
  return r;
}

Result<SurfaceWrite> subdivide_update(const Options& options, ReconstructionState& state, SurfaceMesh& surface) {
  Result<SurfaceWrite> r = run_subdivide(options, state.cache(), surface);
  if (!r) state.cache() = ReconstructionCache{};
  return r;
}

Status reconstruct_update(const Mesh& net, const Options& options, ReconstructionState& state, SurfaceMesh& surface) {
  ReconstructionCache& c = state.cache();
  // A call with nothing changed still re-runs the global stages, as a fresh reconstruction would.
  if (c.built) c.pending_subdivide = true;
  Options whole = options;
  whole.fit_work_per_frame = kWholeFit;
  if (auto r = refine_update(net, whole, state); !r) return Status::failure(r.error());
  if (auto r = subdivide_update(whole, state, surface); !r) return Status::failure(r.error());
  return Status::success();
}

Cage cage_of(const ReconstructionState& state, const Options& options, SurfaceMesh surface) {
  const BaseMesh& base = state.base();
  Cage cage;
  cage.mesh.positions.assign(state.settled_points().begin(), state.settled_points().end());
  cage.mesh.face_offsets = base.face_offsets;
  cage.mesh.face_vertices = base.face_vertices;
  cage.sharp_edges = base.sharp_edges;
  cage.border_corners = base.border_corners;
  cage.levels = options.levels;
  cage.surface = std::move(surface);
  return cage;
}

Result<Cage> reconstruct_cage(const Mesh& net, const Options& options) {
  ReconstructionState state;
  SurfaceMesh surface;
  if (auto s = reconstruct_update(net, options, state, surface); !s) return Result<Cage>::failure(s.error);
  return cage_of(state, options, std::move(surface));
}

Result<SurfaceMesh> reconstruct_surface(const Mesh& net, const Options& options) {
  ReconstructionState state;
  SurfaceMesh surface;
  if (auto s = reconstruct_update(net, options, state, surface); !s) return Result<SurfaceMesh>::failure(s.error);
  return surface;
}

}  // namespace fire::reconstruct
