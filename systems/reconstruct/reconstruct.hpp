#pragma once
// Reconstruction: from the polyline mesh (the curve network) to a smooth surface.
//
//   thesis (chapter 6): triquadrification of faces with more than 4 sides (greedy, by a planarity
//     measure; cuts get straight polylines), N steps of Coons refinement (bilinearly blended Coons
//     patches over the polylines, nearest samples; triangles by the centroid of their edge midpoints),
//     then Catmull-Clark to level L. The surface follows the base mesh, not the drawn curves.
//   fire (default): every face with n sides becomes n quads around a centre, the centre and the spokes
//     sampled from an n-sided transfinite patch over the face's polylines (systems/reconstruct/
//     geometry.hpp); N-1 further Coons steps (linear sampling); a 2-sided face gives 2 quads; then the
//     base points are fitted so that the Catmull-Clark limit surface passes through the drawn
//     polylines (least squares with a fairness term, systems/reconstruct/fit.hpp). A side is a network
//     edge, or, for noisy curves, the two edges at an inner vertex where only they meet, joined
//     (UpdateStats::edges_rejoined, ReconstructionState::joined_vertices).
//
// Both write a SurfaceMesh: the level-L quads with their vertices' limit positions and limit normals.
// The network is read, never written. Incremental use: reconstruct_update() keeps the per-edge and
// per-face results of the previous call in a ReconstructionState and recomputes only the edges stamped
// after the frame it last saw and the faces stamped so, or one of whose edges is; its result equals a
// fresh reconstruction of the same network bit for bit. What stays global: numbering the base mesh,
// Catmull-Clark (its topology and, for FIRE, the fit's factorization are rebuilt only when the base
// mesh's topology changed) and the fit's solves (back-substitutions over the whole base mesh), which the
// frame spreads over the frames after a commit (subdivide_update), showing the surface of the initial base
// points meanwhile.
#include <cstdint>
#include <memory>
#include <string>
#include <span>
#include <vector>

#include "engine/cage.hpp"
#include "engine/mesh.hpp"
#include "engine/polygon_mesh.hpp"
#include "engine/surface.hpp"
#include "systems/reconstruct/face.hpp"

namespace fire::reconstruct {

inline constexpr uint32_t kMaxCoonsSteps = 5;
// fire: a border vertex of the network is a corner of the surface only where the border turns by more
// than this many degrees plus the network's tangent_spread_deg (noise turns the curves' first stretches
// too), the turn measured between the directions in which its two border curves leave it, each towards
// its point kTangentReach of the curve's length away. Elsewhere the border runs smoothly through it
// (thesis: a vertex where a curve merely goes on is no corner).
inline constexpr double kBorderCornerTurnDeg = 30.0;
inline constexpr double kTangentReach = 0.15;
// A noisy curve's border turn is read past the pen's rest at the vertex. Where two border strokes meet, the pen
// rests between them, and a tracked pen drifts a millimetre while it rests: the curve's first dozens of samples
// jitter within that, and the vertex sits where the rest began, off the line both curves then run along (the
// simulated pawn's base). So the direction starts at the curve's last sample within kPauseNoises noise
// deviations of the vertex (in its first half), and reaches at least kCornerReachNoises deviations from there.
// perf/notes/quality.md, "The pawn's base: the pen's rest at a border corner".
inline constexpr double kPauseNoises = 3;
inline constexpr double kCornerReachNoises = 6;
// fire: a side more than this many times as long as the mean side of a face it borders is split into
// twice the pieces, again while it is still so much longer, at most kMaxSideDoublings times: the face's
// quads along it are then not stretched along the curve, and the fit has the base points to follow it
// (the demo dome's longest curve; perf/notes/quality.md, "Long sides get more pieces"). The faces on either
// side then have polygons with the finer split points between their corners.
inline constexpr double kLongSideRatio = 2.0;
inline constexpr uint32_t kMaxSideDoublings = 2;
// fire: where a face's loop turns by at most this many degrees less the network's tangent_spread_deg at
// a corner (measured as for border corners, kTangentReach; noise turns the curves' first stretches, so
// only a corner straight beyond the noise's turning counts), the two sides there are one side of the
// face, split first at that corner, as a curve that ends on another one's middle is; only where every
// face of both sides sees them so (plan_faces in reconstruct.cpp), since a side is split the same way
// for both its faces.
inline constexpr double kStraightCornerTurn = 20.0;
// Surface levels the options allow (the Catmull-Clark library itself refines further).
inline constexpr uint32_t kMaxSurfaceLevels = 6;
// Options::fit_work_per_frame that runs a fit to its end in one call, as a rebuild does.
inline constexpr uint32_t kWholeFit = UINT32_MAX;

struct Options {
  Method method = Method::Fire;
  uint32_t coons_steps = 1;                        // N, 1 .. kMaxCoonsSteps
  uint32_t levels = 3;                             // L, 1 .. kMaxSurfaceLevels
  Planarity planarity = Planarity::LeastSquares;  // the thesis's triquadrification measure
  // FIRE: weight of the fit's fairness term (systems/reconstruct/fit.hpp), 0 to 1. It chooses the face
  // interiors the curves leave open; larger is smoother, smaller follows exactly representable data
  // more closely. With fairness_from_noise, the weight for exact curves: noisy ones raise it
  // (fit_fairness); without, the weight itself (an explicit --fairness).
  double fairness = 1e-3;
  bool fairness_from_noise = true;
  // FIRE, the live frame: the fit's work per frame after a commit (the subdivide system), in base
  // vertices times back-substitutions: a frame runs this over the base mesh's vertex count of them, at
  // least one; kWholeFit for the whole fit in the commit frame. The two frames after a commit that changed
  // the base topology build the limit stencils with the fit's rows and then factorize it. A back-substitution and its target
  // updates cost about in proportion to the base mesh, so a frame's share stays under about 8 ms on the
  // 2-core VM (perf/notes/frame.md, "A fit that stops where noisy curves stop it"); a fit settles within
  // 2 + ceil(iterations x base vertices / 8000) frames of its commit: 6 frames for the at most
  // FitWeights::max_iterations = 110 of a base mesh of up to 280 vertices, 7 for the simulated pawn's 650
  // and its noisy curves' 40 or so.
  uint32_t fit_work_per_frame = 8000;
  friend bool operator==(const Options&, const Options&) = default;
};

// The base mesh handed to subdivision, and the polylines the fit follows along its edges: quads, and
// (FIRE) polygons beside sides split more finely than the Coons steps (kLongSideRatio).
struct BaseMesh : PolygonMesh {
  // Per base face, the slot of the network face it was made from; a network face's base faces are
  // consecutive (the subdivide system groups the surface's quads into patches by it).
  std::vector<uint32_t> face_source;
  std::vector<uint32_t> sharp_edges;  // vertex pairs along network edges marked sharp
  // fire: per vertex, 1 where the border is a corner of the surface (catmull_clark::BaseTopology::
  // border_corners); empty for thesis, whose border keeps Catmull-Clark's EdgeAndCorner rule.
  std::vector<uint8_t> border_corners;
  // One curve per base edge, from curve_ends[2c] to curve_ends[2c+1]: a piece of a network polyline
  // (drawn) or a polyline made inside a face (a triquadrification cut or a spoke).
  std::vector<uint32_t> curve_ends;
  std::vector<uint32_t> curve_offsets{0};
  std::vector<Vec3> curve_points;
  std::vector<uint8_t> curve_drawn;
  std::vector<uint8_t> vertex_drawn;  // the vertex is a network vertex or a sample of a network polyline
  // The drawn curves come first, side by side (a side is a network edge, or edges joined at vertices the
  // base mesh leaves out), each side's pieces from its first vertex to its last: side s has the curves
  // side_curve_offsets[s] to side_curve_offsets[s + 1] - 1.
  std::vector<uint32_t> side_curve_offsets{0};
  uint32_t vertex_count() const { return static_cast<uint32_t>(positions.size()); }
  uint32_t curve_count() const { return static_cast<uint32_t>(curve_offsets.size() - 1); }
  uint32_t side_count() const { return static_cast<uint32_t>(side_curve_offsets.size() - 1); }
  std::span<const Vec3> curve(uint32_t c) const {
    return std::span<const Vec3>(curve_points).subspan(curve_offsets[c], curve_offsets[c + 1] - curve_offsets[c]);
  }
};

// The worst-shaped quad of a base mesh: the largest (longest side)^2 / area, 1 for a square, 1/w for a
// 1 x w rectangle, about 2.4 for a rhombus with 25-degree corners (area from the diagonals' cross product);
// infinite for a quad of zero area.
double worst_quad_aspect(const BaseMesh& base);
// The deviation of the noise on the network's polylines, as a fraction of their mean length: from the
// median third difference of consecutive samples, robust to curvature and to a few outliers; only
// polylines of at least kNoiseSamples samples count (0 when none has that many).
inline constexpr size_t kNoiseSamples = 10;
double noise_estimate(const Mesh& net);
// Noise estimates at or below this are exact curves (sampled limit curves give 2e-5 to 3e-4).
inline constexpr double kExactCurveNoise = 3e-4;
// How far out of one plane the curves leaving a network vertex start, in degrees: the median over the
// vertices where three or more curves with at least three samples meet and no crease does (the curves'
// directions from a parabola through each one's first three samples). Curves of one smooth surface share
// its tangent plane; noise that is smooth along each curve (a tracked pen's) tilts them apart, which the
// third differences of noise_estimate cannot see. 0 when fewer than kSpreadVertices vertices count.
inline constexpr size_t kSpreadVertices = 4;
double tangent_spread_deg(const Mesh& net);
// Over this, curves that noise_estimate finds exact are not: it lies between the spreads of the quality
// table's exact networks and of its correlated-noise ones (perf/notes/quality.md, "Correlated noise seen
// where curves meet").
inline constexpr double kDisagreeingTangentsDeg = 2.0;
// The noise the fit's fairness follows: noise_estimate, except for curves it finds exact whose tangents
// disagree (tangent_spread_deg over kDisagreeingTangentsDeg), which count as noisy as the noise at which
// the fairness reaches kNoisyFairness.
double fit_noise(const Mesh& net);
// The same from the two measures, where they are already known.
double fit_noise(double noise, double spread_deg);
// The fairness noisy curves reach, and keep up to kNoisierCurves: on pawn, rook and torus at 1 to 4 % noise
// and on the simulated tracked drawing it gives fewer folds and a smaller rms and hausdorff than 1e-3 or
// 1e-2 (perf/notes/quality.md, "Thin quads keep their transfinite shape; the fairness follows the noise").
inline constexpr double kNoisyFairness = 0.1;
// Above this noise estimate (chosen by a sweep over the noisy networks' estimates) the fairness grows again
// with the square of the noise: it keeps the pawn at 4 % from folding and the rook from folding as much,
// while the torus at 1 and 2 %, whose big faces have no curve inside and flatten under more, stays at
// kNoisyFairness (perf/notes/quality.md, "The fairness grows again above 4 % noise").
inline constexpr double kNoisierCurves = 1.3e-2;
inline constexpr double kNoisiestFairness = 1.0;  // the top of --fairness's range
// The fairness the fit uses for a network whose noise_estimate is `noise`: Options::fairness for exact
// curves, growing with the square of the noise above kExactCurveNoise up to kNoisyFairness, and again
// above kNoisierCurves up to kNoisiestFairness.
double fit_fairness(const Options& options, double noise);
// How the fit reads the polylines between their samples for that noise: smooth for exact curves (their
// samples lie on a smooth curve, inside whose bends the chords cut by about the network_max goal),
// linear above kExactCurveNoise (a cubic through noisy samples swings past them, and the surface folds;
// perf/notes/quality.md, "Exact curves are read on the smooth curve through their samples"). An explicit
// --fairness estimates no noise, so it reads them smooth.
Sampling fit_targets(double noise);
// A noisy curve reaching less far than kShortCurveNoises noise deviations from its ends is short: its shape
// is mostly the noise's. The deviation is the larger of fit_noise and the sideways step of a curve turned
// by tangent_spread_deg over kTangentReach of its length (correlated noise, which fit_noise does not
// measure), times the mean polyline length; none for exact curves or an explicit --fairness. The surface
// takes a short curve as its chord plus a part of its departure from the chord, none below
// kChordCurveNoises deviations, growing linearly to all of it. The rook's noisy folds were
// nearly all at the small hole in its bottom, whose curves reach only a few deviations and whose
// scribbles crossed their neighbours, while the torus's shortest curves reach more than kShortCurveNoises
// (perf/notes/quality.md, "Short noisy curves taken nearer their chords"). The drawn
// curves stay as drawn: only the surface's polylines (the refine stage's edge splits) change.
inline constexpr double kChordCurveNoises = 3;
inline constexpr double kShortCurveNoises = 6;
// Where a noisy curve leaves a vertex, its first samples point any way within the noise: a tracked pen's start
// is a millimetre off the vertex it snaps to, and curves that leave a pole of 12 a few degrees apart cross one
// another there, which folds the surface between them (the simulated pawn's pole and its head's ring). The
// surface takes each side's stretch within kEndStraightNoises deviations of its ends, times the
// vertex's valence over 4 where more than 4 curves meet, as straight: the samples move onto the line of their
// mean direction from the vertex, fully at the vertex and blending back to the drawn curve at the stretch's
// end. A stretch is at most kEndStraightShare of the side's length, twice that at a crowded vertex.
// Border sides too: their corners are read on the drawn curves (kPauseNoises), and a stretch taken straight keeps
// its side's direction there. perf/notes/quality.md, "The pawn's pole: a curve dragged through it, and curves
// crossing where they leave it", and "The pawn's base: the pen's rest at a border corner".
inline constexpr double kEndStraightNoises = 6;
inline constexpr double kEndStraightShare = 0.25;
// The same measure for one base face, which must be a quad.
double quad_aspect(const BaseMesh& base, uint32_t face);

// What the last reconstruct_update() did.
struct UpdateStats {
  size_t edges_recomputed = 0;
  // Of those, unchanged edges redone because how much of their shape the surface takes changed with the
  // network's noise (short noisy curves, kShortCurveNoises): their faces are redone too, wherever the edit was.
  size_t edges_rescaled = 0;
  // Of those, unchanged sides redone because the vertices joined into them changed (joined_vertices in
  // reconstruct.cpp: an edit at the vertex, or the network's noise crossing kExactCurveNoise): their two
  // faces are redone too.
  size_t edges_rejoined = 0;
  // Of those, unchanged sides redone because the pieces they are split into changed (kLongSideRatio: a face
  // they border changed its mean side): their faces are redone too.
  size_t edges_resplit = 0;
  size_t faces_recomputed = 0;
  bool topology_rebuilt = false;  // subdivision topology and (fire) the fit's factorization were rebuilt
  uint32_t fit_iterations = 0;    // solves of the fit (fire), each a back-substitution
  double fit_rms = 0;             // fire: rms distance of the fitted limit points to their targets on drawn curves
};

struct ReconstructionCache;

// The results of the previous reconstruction, for incremental updates.
class ReconstructionState {
 public:
  ReconstructionState();
  ~ReconstructionState();
  ReconstructionState(ReconstructionState&&) noexcept;
  ReconstructionState& operator=(ReconstructionState&&) noexcept;
  const UpdateStats& last_update() const;
  const BaseMesh& base() const;  // the base mesh of the last successful update
  // The base points of the last settled surface (the fitted ones, for fire): with base()'s faces, sharp
  // edges and border corners, the subdivision cage whose Catmull-Clark limit that surface is.
  std::span<const Vec3> settled_points() const;
  bool fitting() const;          // a fit runs over the next subdivide_update calls
  // fire: how many curves the last update took nearer their chords as short noisy ones (kShortCurveNoises).
  uint32_t short_curves() const;
  // fire: how many network vertices the last update joined the two curves at (noisy curves meeting at an
  // inner vertex of valence 2, which the base mesh leaves out: reconstruct.cpp, joined_vertices).
  uint32_t joined_vertices() const;
  ReconstructionCache& cache() { return *cache_; }

 private:
  std::unique_ptr<ReconstructionCache> cache_;
};

// What the frame's refine and subdivide systems share: the incremental state and the last problem, in
// words ("" while the surface follows the network).
struct SurfaceBuild {
  ReconstructionState state;
  std::string problem;
  bool clear_surface = false;  // the network lost its last face: the surface must go too
  uint64_t updates = 0;        // refine updates that produced a new base mesh
};

// Rejects options out of range, with the option and its range named.
Status check_options(const Options& options);
// Rejects, with the element and the problem named: options out of range (check_options), a network that breaks its
// invariants (non-finite coordinates included), no faces, a face with fewer than 3 edges (thesis), a
// polyline of zero length, two consecutive polyline points that coincide, two corners of a face that
// coincide.
Status check_reconstruction_input(const Mesh& net, const Options& options);

// Reconstructs `net` into `surface`, reusing what `state` holds from the previous call where the change
// stamps say nothing changed since then. Writes made in the frame of that call after it ran are not seen:
// the caller starts a new frame (Mesh::begin_frame) before editing again. On failure
// `surface` is left as it was and `state` is emptied, so the next call rebuilds everything.
Status reconstruct_update(const Mesh& net, const Options& options, ReconstructionState& state, SurfaceMesh& surface);

// What a refine_update call did with the base mesh.
enum class Refined : uint8_t {
  Unchanged,  // nothing changed since the last call: nothing was done
  Assembled,  // the base mesh was assembled anew and may differ from the last one
};

// What a subdivide_update call wrote into its `surface`.
enum class SurfaceWrite : uint8_t {
  None,         // nothing new: `surface` is left as it was
  Provisional,  // the new base mesh's last level from its initial points (the transfinite patches); a fit runs
  Settled,      // the final surface, equal to a rebuild's bit for bit
};

// reconstruct_update in the two halves the frame runs as systems. refine_update recomputes the changed
// edges and faces and assembles the base mesh; it returns Refined::Unchanged, doing nothing, when nothing
// changed since its last call (a new base mesh abandons a fit still running). subdivide_update then, for a new base
// mesh, rebuilds topology where needed and evaluates into `surface` the new base mesh's provisional
// surface, its last level's points with their quads' normals (fire, unless the whole fit runs in the same
// call: kWholeFit). If the topology changed, the next call (fire) builds the limit stencils and the fit's
// rows and the one after factorizes it; then, or at once with the old factorization, the calls run the fit's back-substitutions, as many each as Options::fit_work_per_frame allows, and write the
// settled surface when the fit ends. On failure the state is emptied as above.
Result<Refined> refine_update(const Mesh& net, const Options& options, ReconstructionState& state);
Result<SurfaceWrite> subdivide_update(const Options& options, ReconstructionState& state, SurfaceMesh& surface);

// One reconstruction from scratch.
Result<SurfaceMesh> reconstruct_surface(const Mesh& net, const Options& options);

// The subdivision cage of a reconstruction: the base mesh with its settled (fitted) points, its infinitely
// sharp edges and the border's corners. Catmull-Clark refined `levels` times and pushed to the limit, it
// gives its `surface`, which is what reconstruct_surface returns.
using Cage = fire::Cage;
Result<Cage> reconstruct_cage(const Mesh& net, const Options& options);
// The same from a state whose last update (reconstruct_update) wrote `surface`, settled.
Cage cage_of(const ReconstructionState& state, const Options& options, SurfaceMesh surface);

}  // namespace fire::reconstruct
