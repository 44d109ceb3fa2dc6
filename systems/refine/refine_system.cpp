#include "systems/refine/refine_system.hpp"

namespace fire {

void refine_system(const Mesh& mesh, const reconstruct::Options& options, reconstruct::SurfaceBuild& build) {
  if (mesh.face_count() == 0) {
    // An open border or an empty network has no surface; that is not a problem to report.
    if (build.state.base().face_count() > 0 || !build.problem.empty()) build.clear_surface = true;
    build.state = {};
    build.problem.clear();
    return;
  }
  Result<reconstruct::Refined> changed = reconstruct::refine_update(mesh, options, build.state);
  if (!changed) {
    build.problem = changed.error();
    return;
  }
  if (*changed == reconstruct::Refined::Assembled) {
    build.problem.clear();
    ++build.updates;
  }
}

}  // namespace fire
