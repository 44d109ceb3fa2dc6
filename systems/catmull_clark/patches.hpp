#pragma once
// Internal to fire_subdivide: the two halves of build_refinement.
#include "systems/catmull_clark/catmull_clark.hpp"

namespace fire::catmull_clark::detail {

// The levels alone (Refinement::patches left empty).
Result<Refinement> build_levels(const BaseTopology& base, const RefinementOptions& options);

// Gives a refinement of kMinPatchLevels to kMaxPatchLevels levels its regular patches and renumbers
// its last level (see RegularPatches); leaves it as it is where that path does not apply (no regular
// base quad, or a vertex in no face).
void plan_regular_patches(const BaseTopology& base, Refinement& refinement);

}  // namespace fire::catmull_clark::detail
