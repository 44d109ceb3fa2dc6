#include "systems/subdivide/subdivide_system.hpp"

namespace fire {

void subdivide_system(const reconstruct::Options& options, const FrameTime& frame, reconstruct::SurfaceBuild& build,
                      SurfaceLevels& surface) {
  if (build.clear_surface) {
    const uint64_t version = surface.topology_version + 1;
    surface = {};
    surface.topology_version = version;
    surface.frame = frame.index;
    build.clear_surface = false;
  }
  if (!build.problem.empty()) return;
  SurfaceMesh mesh;
  if (Status s = reconstruct::subdivide_update(options, build.state, mesh); !s) {
    build.problem = s.error;
    return;
  }
  // subdivide_update leaves `mesh` empty when refine found nothing new.
  if (mesh.face_count() == 0) return;
  if (!assign_quads(mesh, frame.index, surface)) {
    build.problem = "internal error: the subdivided surface has a face that is not a quad";
    return;
  }
  surface.level = options.levels;
  surface.settled = true;
}

}  // namespace fire
