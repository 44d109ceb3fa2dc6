#pragma once
// The refine system (thesis 6.1-6.2, FIRE's n-sided patches): turns the faces and edges that changed
// since it last ran into base quads with their transfinite patches, and assembles the base mesh that
// the subdivide system refines. Reads the mesh's change stamps; recomputes only what they name.
#include "engine/mesh.hpp"
#include "systems/reconstruct/reconstruct.hpp"

namespace fire {

void refine_system(const Mesh& mesh, const reconstruct::Options& options, reconstruct::SurfaceBuild& build);

}  // namespace fire
