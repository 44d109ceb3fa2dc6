#pragma once
// Wavefront OBJ polygon meshes: `v` and `f` lines (f accepts v, v/vt, v//vn, v/vt/vn and negative indices);
// every other statement is ignored. Errors name the file, the line and the problem.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "engine/common.hpp"

namespace fire {

struct PolygonMesh {
  std::vector<Vec3> positions;
  std::vector<uint32_t> face_offsets{0};  // face f uses face_vertices[face_offsets[f] .. face_offsets[f+1])
  std::vector<uint32_t> face_vertices;    // 0-based vertex indices
  size_t face_count() const { return face_offsets.size() - 1; }
  uint32_t face_size(size_t f) const { return face_offsets[f + 1] - face_offsets[f]; }
};

// Parses OBJ text; `source` names it in messages. Rejects: no vertices or faces, non-finite coordinates,
// faces with fewer than 3 vertices, indices out of range, a vertex repeated within one face.
Result<PolygonMesh> parse_obj(std::string_view text, const std::string& source);
Result<PolygonMesh> read_obj(const std::string& path);

}  // namespace fire
