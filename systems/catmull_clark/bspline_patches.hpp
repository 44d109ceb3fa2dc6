#pragma once
// A Catmull-Clark cage's limit surface as bicubic B-spline patches (engine/bspline.hpp), for CAD export.
//
// A quad whose corners are regular is a uniform bicubic B-spline patch already: in the interior a smooth
// corner of valence 4 among quads; on a border or an infinitely sharp crease, the faces on its side of the
// sharp edges are what counts: a crease vertex with two quads on the face's side, or a corner vertex with
// the face alone there, whose missing control points are the phantoms P = 2 B - I across the sharp edge
// (OpenSubdiv's boundary and corner patches; exact, since the B-spline rules of that extended grid
// reproduce the crease and corner rules). Those patches are exact. Every other face (n-gons, faces at
// extraordinary vertices, darts, border vertices of other kinds) is subdivided, with the 1-ring of faces it
// depends on, one level at a time: its children that are regular become exact patches, the others go on.
// From level 1 on, the faces still irregular are fitted: each side's limit curve by a cubic through its
// ends (once per side, so both faces of a side share it exactly), then the inner four control points by
// least squares against the limit at (2^sample_levels + 1)^2 points of the face, each sample's parameter
// moved to its nearest point between rounds. Faces joined by sides are kept or split together: kept when
// their largest distance to the limit at the samples is within 0.8 of the tolerance (a margin for the
// points between samples), or at max_depth; else subdivided again. A side between a fitted face and an
// exact one is a cubic limit curve, which the fit reproduces; exact faces of different levels meet along
// pieces of the same cubic (a T-junction without a gap, which sewing splits).
#include <cstdint>
#include <span>
#include <vector>

#include "engine/bspline.hpp"
#include "engine/cage.hpp"
#include "engine/common.hpp"
#include "systems/catmull_clark/catmull_clark.hpp"

namespace fire::catmull_clark {

struct BsplineOptions {
  double tolerance = 1e-4;     // largest distance of a fitted patch to the limit, a fraction of the diagonal
  uint32_t max_depth = 6;      // levels of subdivision at most; faces still irregular there are fitted anyway
  uint32_t sample_levels = 4;  // a fit's samples: the limit points of its face refined this many levels (2 to 6)
};

struct BsplineConversion {
  BsplinePatches patches;
  // Where patch p lies: base face patch_face[p] (level 0) or, refined path_offsets[p + 1] - path_offsets[p]
  // levels, the child quad of corner path_corners[path_offsets[p]] of that face (0 .. its size - 1), then
  // of that quad's corner path_corners[...+1], and so on, in subdivide.hpp's numbering (the child quad of
  // corner c is quad c of the next level). The patch's u runs from the quad's first corner to its second,
  // v from the first to its fourth.
  std::vector<uint32_t> patch_face;
  std::vector<uint32_t> path_offsets{0};
  std::vector<uint32_t> path_corners;
  uint32_t exact = 0, fitted = 0;
  uint32_t fit_level = 0;  // the deepest level of a fitted patch (0 when none is fitted)
  // The largest distance of a fitted patch to the limit at its samples, as a fraction of `diagonal`: that of
  // the limit surface's bounding box (around the limit positions of the base vertices and level-1 points), in
  // the cage's units.
  double max_fit_error = 0;
  double diagonal = 0;
  uint32_t patch_level(size_t p) const { return path_offsets[p + 1] - path_offsets[p]; }
};

// Converts the limit surface of the cage `topology` with `points` (one per vertex). Errors: those of
// build_refinement, a point that is not finite, options out of range; all name the element.
Result<BsplineConversion> bspline_patches(const BaseTopology& topology, std::span<const Vec3> points,
                                          const BsplineOptions& options = {});

// The same for a cage with its sharp edges and border corners.
Result<BsplineConversion> bspline_patches(const Cage& cage, const BsplineOptions& options = {});

// Patch p at (u, v) in [0, 1]^2.
Vec3 evaluate_patch(const BsplinePatches& patches, size_t p, double u, double v);
// The distance from x to patch p, at the point nearest to x found from (u, v) by Gauss-Newton steps (an
// upper bound of the true distance; equal to it when (u, v) starts in the right basin).
double distance_to_patch(const BsplinePatches& patches, size_t p, const Vec3& x, double u, double v);

}  // namespace fire::catmull_clark
