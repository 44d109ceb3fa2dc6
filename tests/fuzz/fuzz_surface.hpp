#pragma once
// The surface readers' shared properties (PLY, STL and glb targets): a failed decode names the input
// and the problem; a decoded surface is one encode_surface accepts (faces of 3 or more distinct vertices
// in range, finite coordinates, normals absent or one per vertex and finite), and written back in its
// format it decodes to the same positions and faces.
#include <cmath>
#include <cstdint>
#include <string_view>

#include "platform/surface_io.hpp"
#include "tests/fuzz/fuzz_check.hpp"

namespace fire::fuzz {

inline void check_surface_invariants(const SurfaceMesh& s) {
  FUZZ_CHECK(!s.positions.empty() && s.face_count() > 0, "a decoded surface has vertices and faces");
  FUZZ_CHECK(s.face_offsets.front() == 0 && s.face_offsets.back() == s.face_vertices.size(),
             "face offsets cover the face vertex list");
  for (size_t f = 0; f < s.face_count(); ++f) {
    FUZZ_CHECK(s.face_offsets[f] < s.face_offsets[f + 1] && s.face_size(f) >= 3, "faces have 3 or more vertices");
    for (uint32_t c = s.face_offsets[f]; c < s.face_offsets[f + 1]; ++c) {
      FUZZ_CHECK(s.face_vertices[c] < s.positions.size(), "face vertices are in range");
      for (uint32_t d = s.face_offsets[f]; d < c; ++d)
        FUZZ_CHECK(s.face_vertices[d] != s.face_vertices[c], "a face uses each vertex once");
    }
  }
  for (const Vec3& p : s.positions) FUZZ_CHECK(p.allFinite(), "positions are finite");
  FUZZ_CHECK(s.normals.empty() || s.normals.size() == s.positions.size(), "normals absent or one per vertex");
  for (const Vec3& n : s.normals) FUZZ_CHECK(n.allFinite(), "normals are finite");
}

inline int fuzz_surface(const uint8_t* data, size_t size, SurfaceFormat format) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const Result<SurfaceMesh> surface = decode_surface(bytes, format, kSource);
  if (!surface) {
    FUZZ_CHECK(names_input_and_problem(surface.error()), "an error names the input and the problem");
    return 0;
  }
  check_surface_invariants(*surface);
  const Result<std::string> written = encode_surface(*surface, format, kSource, LengthUnit::Metre);
  FUZZ_CHECK(written.ok(), "a decoded surface can be written in its format");
  const Result<SurfaceMesh> again = decode_surface(*written, format, kSource);
  FUZZ_CHECK(again.ok(), "a written surface decodes");
  check_surface_invariants(*again);
  // Written in metres: a file in metres comes back bit for bit; one in mm or cm was divided into metres on reading,
  // which a float holds to its own precision only.
  FUZZ_CHECK(again->positions.size() == surface->positions.size(), "decode -> encode -> decode keeps the vertices");
  for (size_t v = 0; v < surface->positions.size(); ++v)
    for (int k = 0; k < 3; ++k) {
      const double a = again->positions[v][k], b = surface->positions[v][k];
      // Relative to the value, and absolute at the bottom of a float's range, where subnormals hold fewer bits.
      FUZZ_CHECK(a == b || std::abs(a - b) <= 1.2e-7 * std::max(std::abs(a), std::abs(b)) + 1.5e-45,
                 "decode -> encode -> decode keeps the positions (to a float's precision)");
    }
  FUZZ_CHECK(again->face_offsets == surface->face_offsets && again->face_vertices == surface->face_vertices,
             "decode -> encode -> decode keeps the faces");
  // The writer makes every normal unit length (see encode_surface).
  for (const Vec3& n : again->normals)
    FUZZ_CHECK(n.isZero() || std::abs(n.norm() - 1) < 1e-5, "written normals are unit length or zero");
  return 0;
}

}  // namespace fire::fuzz
