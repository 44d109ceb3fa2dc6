#pragma once
// Bicubic B-spline patches as plain data: the limit surface in the form CAD systems take
// (systems/catmull_clark/bspline_patches.hpp makes them from a cage, platform/cad writes them as STEP or IGES).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "engine/common.hpp"

namespace fire {

// Every patch is one bicubic span: a B-spline of degree 3 in u and in v over the clamped knots
// {0, 0, 0, 0, 1, 1, 1, 1}, which is the Bezier form, so its corners are its corner control points and
// neighbours that share a side share that side's four control points. Patch p's control point (i, j),
// i along u and j along v, is controls[16 p + 4 j + i]; u x v points to the side the cage's faces are
// counter-clockwise from (outside). Positions in metres, as everywhere in FIRE.
struct BsplinePatches {
  std::vector<Vec3> controls;   // 16 per patch
  std::vector<uint8_t> fitted;  // per patch: 1 fitted to the limit surface within a tolerance, 0 exact
  size_t patch_count() const { return fitted.size(); }
  const Vec3& control(size_t patch, uint32_t i, uint32_t j) const { return controls[16 * patch + 4 * j + i]; }
};

}  // namespace fire
