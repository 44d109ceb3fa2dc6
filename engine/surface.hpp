#pragma once
// A polygon surface: what reconstruction produces and export writes. Faces as flat offsets + indices.
#include <cstdint>
#include <vector>

#include "engine/common.hpp"

namespace fire {

struct SurfaceMesh {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;              // per vertex; empty when not computed
  std::vector<uint32_t> face_offsets{0};  // face f: face_vertices[face_offsets[f] .. face_offsets[f+1])
  std::vector<uint32_t> face_vertices;
  size_t face_count() const { return face_offsets.size() - 1; }
  uint32_t face_size(size_t f) const { return face_offsets[f + 1] - face_offsets[f]; }
};

}  // namespace fire
