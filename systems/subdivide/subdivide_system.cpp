#include "systems/subdivide/subdivide_system.hpp"

#include "engine/assert.hpp"

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
  const Result<reconstruct::SurfaceWrite> wrote =
      reconstruct::subdivide_update(options, build.state, mesh);
  if (!wrote) {
    build.problem = wrote.error();
    return;
  }
  if (*wrote == reconstruct::SurfaceWrite::None) return;
  if (!assign_quads(mesh, frame.index, surface)) {
    build.problem = "internal error: the subdivided surface has a face that is not a quad";
    return;
  }
  surface.level = options.levels;
  surface.settled = *wrote == reconstruct::SurfaceWrite::Settled;
  // Each base face of n corners has n * 4^(L-1) consecutive last-level quads, in base face order, so a
  // network face's quads are one range: its patch.
  const reconstruct::BaseMesh& base = build.state.base();
  const std::vector<uint32_t>& source = base.face_source;
  const uint32_t per_corner = 1u << (2 * (options.levels - 1));
  FIRE_ASSERT(!source.empty() && surface.quad_count() == size_t{base.face_offsets.back()} * per_corner,
              "the last level has 4^(L-1) quads per base face corner");
  surface.patch_offsets.clear();
  surface.patch_keys.clear();
  for (uint32_t f = 0; f < source.size(); ++f)
    if (f == 0 || source[f] != source[f - 1]) {
      surface.patch_offsets.push_back(base.face_offsets[f] * per_corner);
      surface.patch_keys.push_back(source[f]);
    }
  surface.patch_offsets.push_back(surface.quad_count());
}

}  // namespace fire
