#pragma once
// Polygon meshes as flat arrays: face f uses face_vertices[face_offsets[f] .. face_offsets[f+1]), 0-based
// vertex indices. PolygonFaces holds those two arrays for any kind of corner (a vertex index, or reconstruction's
// reference to a vertex not numbered yet); Catmull-Clark's levels extend them. PolygonMesh adds positions (what
// the file readers return, the base of the exported surface and of reconstruction's base mesh); PolygonMeshView
// borrows them, which is how systems take a mesh (they read no files).
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "engine/common.hpp"

namespace fire {

struct PolygonMeshView {
  std::span<const Vec3> positions;
  std::span<const uint32_t> face_offsets;
  std::span<const uint32_t> face_vertices;
  std::string_view source = {};  // names the mesh in error messages (a file name); may be empty
};

template <class Corner>
struct PolygonFaces {
  std::vector<uint32_t> face_offsets{0};  // face count + 1
  std::vector<Corner> face_vertices;      // per corner
  uint32_t face_count() const { return static_cast<uint32_t>(face_offsets.size() - 1); }
  uint32_t face_size(size_t f) const { return face_offsets[f + 1] - face_offsets[f]; }
  std::span<const Corner> face(size_t f) const {
    return std::span<const Corner>(face_vertices).subspan(face_offsets[f], face_size(f));
  }
};

struct PolygonMesh : PolygonFaces<uint32_t> {
  std::vector<Vec3> positions;
  PolygonMeshView view(std::string_view source = {}) const { return {positions, face_offsets, face_vertices, source}; }
};

}  // namespace fire
