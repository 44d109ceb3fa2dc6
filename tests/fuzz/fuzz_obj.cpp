// OBJ reader (parse_obj): a failed parse names the input, the line and the problem; a parsed mesh has
// finite positions and faces of 3 or more distinct vertices in range, and written back as an OBJ surface
// it reads back to the same positions and faces; its OpenSubdiv tags are read or refused in words.
#include <cstdint>
#include <string_view>

#include "platform/obj.hpp"
#include "platform/surface_io.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace fire;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  Result<PolygonMesh> mesh = parse_obj(text, fuzz::kSource);
  if (!mesh) {
    FUZZ_CHECK(fuzz::names_input_and_problem(mesh.error()), "an error names the input and the problem");
    return 0;
  }
  FUZZ_CHECK(!mesh->positions.empty() && mesh->face_count() > 0, "a parsed mesh has vertices and faces");
  for (const Vec3& p : mesh->positions) FUZZ_CHECK(p.allFinite(), "positions are finite");
  FUZZ_CHECK(mesh->face_offsets.front() == 0 && mesh->face_offsets.back() == mesh->face_vertices.size(),
             "face offsets cover the face vertex list");
  for (size_t f = 0; f < mesh->face_count(); ++f) {
    FUZZ_CHECK(mesh->face_offsets[f] < mesh->face_offsets[f + 1], "face offsets increase");
    FUZZ_CHECK(mesh->face_size(f) >= 3, "faces have 3 or more vertices");
    for (uint32_t c = mesh->face_offsets[f]; c < mesh->face_offsets[f + 1]; ++c) {
      FUZZ_CHECK(mesh->face_vertices[c] < mesh->positions.size(), "face vertices are in range");
      for (uint32_t d = mesh->face_offsets[f]; d < c; ++d)
        FUZZ_CHECK(mesh->face_vertices[d] != mesh->face_vertices[c], "a face uses each vertex once");
    }
  }
  // OpenSubdiv's tags: refused in words, or creases between vertices that exist and corners one flag per vertex.
  const Result<SubdivisionTags> tags = parse_obj_tags(text, fuzz::kSource, *mesh);
  if (!tags) {
    FUZZ_CHECK(fuzz::names_input_and_problem(tags.error()), "a refused tag names the input and the problem");
  } else {
    FUZZ_CHECK(tags->sharp_edges.size() % 2 == 0, "creases are vertex pairs");
    for (uint32_t v : tags->sharp_edges) FUZZ_CHECK(v < mesh->positions.size(), "crease vertices are in range");
    FUZZ_CHECK(tags->border_corners.empty() || tags->border_corners.size() == mesh->positions.size(),
               "border corners are one flag per vertex");
  }
  SurfaceMesh surface;
  surface.positions = mesh->positions;
  surface.face_offsets = mesh->face_offsets;
  surface.face_vertices = mesh->face_vertices;
  const Result<std::string> written = encode_surface(surface, SurfaceFormat::Obj, fuzz::kSource, LengthUnit::Metre);
  FUZZ_CHECK(written.ok(), "a parsed mesh can be written");
  const Result<PolygonMesh> again = parse_obj(*written, fuzz::kSource);
  FUZZ_CHECK(again.ok(), "a written mesh parses");
  FUZZ_CHECK(again->positions == mesh->positions, "parse -> write -> parse keeps the positions");
  FUZZ_CHECK(again->face_offsets == mesh->face_offsets && again->face_vertices == mesh->face_vertices,
             "parse -> write -> parse keeps the faces");
  return 0;
}
