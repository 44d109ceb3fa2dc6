#pragma once
// Surfaces as engine data.
//
// SurfaceMesh: a polygon surface with per-vertex normals, what export writes and the file readers return.
// SurfaceLevels: the live surface that refine and subdivide write and the renderer, the exporters and
// `fire eval` read: the last subdivision level's limit positions and normals, its quads as one flat
// index array, the quads grouped by the network face they come from, a topology version, the range
// changed in the last write, and whether it has settled.
#include <cstdint>
#include <vector>

#include "engine/change.hpp"
#include "engine/common.hpp"
#include "engine/hash.hpp"
#include "engine/polygon_mesh.hpp"

namespace fire {

struct SurfaceMesh : PolygonMesh {
  std::vector<Vec3> normals;  // per vertex; empty when not computed
};

struct SurfaceLevels {
  uint32_t level = 0;           // subdivision level the quads belong to (0: no surface yet)
  std::vector<Vec3> positions;  // limit position per vertex of that level (its points while not `settled`)
  std::vector<Vec3> normals;    // unit limit normal per vertex (its quads' normals while not `settled`)
  std::vector<uint32_t> quads;  // 4 vertex indices per quad, counter-clockwise seen from the front
  // Quads by patch: patch p owns quads [patch_offsets[p], patch_offsets[p+1]) and is named by
  // patch_keys[p] (the subdivide system: its network face slot), so that a reader holding a copy (the
  // renderer) keeps the patches a commit left alone although the numbering around them moved. Empty
  // (assign_quads, a loaded snapshot): the whole surface is one patch. Outside surface_hash, not saved.
  std::vector<uint32_t> patch_offsets;
  std::vector<uint32_t> patch_keys;
  // Bumped whenever `quads` or the vertex count change; a reader holding index buffers re-uploads them.
  uint64_t topology_version = 0;
  Frame frame = 0;              // frame of the last write
  ChangedRange changed;         // vertices whose position or normal was written in `frame`
  // False while the surface is provisional: new faces shown from their transfinite patches (the last
  // level's points, not pushed to the limit), the fit that passes through the curves still converging
  // over the next frames.
  bool settled = true;

  uint32_t vertex_count() const { return static_cast<uint32_t>(positions.size()); }
  uint32_t quad_count() const { return static_cast<uint32_t>(quads.size() / 4); }
  uint32_t patch_count() const { return patch_keys.empty() ? 1u : static_cast<uint32_t>(patch_keys.size()); }
  // Quads [first, end) of patch p and its key (kNone for the whole surface as one patch).
  uint32_t patch_begin(uint32_t p) const { return patch_keys.empty() ? 0 : patch_offsets[p]; }
  uint32_t patch_end(uint32_t p) const { return patch_keys.empty() ? quad_count() : patch_offsets[p + 1]; }
  uint32_t patch_key(uint32_t p) const { return patch_keys.empty() ? kNone : patch_keys[p]; }
  bool empty() const { return quads.empty(); }
};

// FNV-1a 64 over the level, positions, normals and quads: with the pools' hash, what a replay must
// reproduce bit for bit. Versions, frames and ranges are bookkeeping and excluded.
inline uint64_t surface_hash(const SurfaceLevels& s) {
  Fnv1a h;
  h.mix(&s.level, sizeof s.level);
  h.mix_array(s.positions);
  h.mix_array(s.normals);
  h.mix_array(s.quads);
  return h.value;
}

// The same surface as a polygon mesh, for export.
inline SurfaceMesh to_surface_mesh(const SurfaceLevels& s) {
  SurfaceMesh m;
  m.positions = s.positions;
  m.normals = s.normals;
  m.face_vertices = s.quads;
  m.face_offsets.resize(s.quad_count() + 1);
  for (uint32_t q = 0; q <= s.quad_count(); ++q) m.face_offsets[q] = 4 * q;
  return m;
}

// Replaces `out` with a quad mesh (every face must have 4 vertices, normals present) written at `now`:
// positions always count as changed; the topology version moves only when the quads or the vertex
// count differ from what `out` held; the patches are cleared (one patch). Returns false, leaving `out`
// alone, when a face is not a quad.
inline bool assign_quads(const SurfaceMesh& mesh, Frame now, SurfaceLevels& out) {
  for (size_t f = 0; f < mesh.face_count(); ++f)
    if (mesh.face_size(f) != 4) return false;
  if (mesh.normals.size() != mesh.positions.size()) return false;
  bool same_topology = out.quads == mesh.face_vertices && out.positions.size() == mesh.positions.size();
  if (!same_topology) {
    out.quads = mesh.face_vertices;
    ++out.topology_version;
  }
  out.patch_offsets.clear();
  out.patch_keys.clear();
  out.positions = mesh.positions;
  out.normals = mesh.normals;
  out.frame = now;
  out.changed = {0, static_cast<uint32_t>(mesh.positions.size())};
  return true;
}

}  // namespace fire
