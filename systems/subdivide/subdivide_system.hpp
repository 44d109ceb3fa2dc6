#pragma once
// The subdivide system: when refine left a new base mesh, rebuilds Catmull-Clark topology (and the
// fit's factorization) only if the base topology changed, fits the base points so the limit surface
// passes through the curves, evaluates the limit positions and normals through the stencils, and writes
// them to the engine's SurfaceLevels for the renderer and the exporters, the quads grouped by network
// face (SurfaceLevels' patches).
#include "engine/surface.hpp"
#include "engine/scheduler.hpp"
#include "systems/reconstruct/reconstruct.hpp"

namespace fire {

void subdivide_system(const reconstruct::Options& options, const FrameTime& frame, reconstruct::SurfaceBuild& build,
                      SurfaceLevels& surface);

}  // namespace fire
