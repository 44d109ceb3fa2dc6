#pragma once
// The subdivide system: when refine left a new base mesh, rebuilds Catmull-Clark topology and limit
// stencils only if the base topology changed, evaluates the limit positions and normals of the base
// mesh's initial points (the transfinite patches) through the stencils and writes them to the engine's
// SurfaceLevels, not settled, for the renderer and the exporters, the quads grouped by network face
// (SurfaceLevels' patches). The next two frames build the fit's rows and factorize it if the topology
// changed; from then on each frame runs Options::fit_work_per_frame's share of the back-substitutions of
// the fit that makes the limit surface pass through the curves, and the frame the fit ends in writes the
// fitted surface, settled (equal to a rebuild's bit for bit). A new base mesh abandons a fit still
// running. Work per frame is a count, never a clock.
#include "engine/surface.hpp"
#include "engine/scheduler.hpp"
#include "systems/reconstruct/reconstruct.hpp"

namespace fire {

void subdivide_system(const reconstruct::Options& options, const FrameTime& frame, reconstruct::SurfaceBuild& build,
                      SurfaceLevels& surface);

}  // namespace fire
