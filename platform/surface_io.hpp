#pragma once
// Surface export: OBJ (v, vn, f v//vn, polygons kept), binary little-endian PLY (float xyz + normal,
// uchar/int face lists), binary STL (fan-triangulated, facet normals) and glTF 2.0 binary (.glb:
// POSITION with min/max, NORMAL, uint32 triangle indices). Every write goes through write_file_atomic,
// so a failed export leaves no partial file. The readers take back exactly what the writers produce;
// they exist for tests and for `fire eval`, not as general importers.
#include <cstdint>
#include <string>
#include <string_view>

#include "engine/common.hpp"
#include "engine/surface.hpp"

namespace fire {

enum class SurfaceFormat { Obj, Ply, Stl, Glb };

// The length unit of a mesh export. FIRE works in metres; OBJ, PLY and STL are written in the unit asked,
// millimetres by default (what slicers and CAD importers assume of a file without one), and +Z up, each
// saying so in a comment or header: OBJ `# units: mm, up: +Z`, PLY `comment units mm` and `comment up +Z`,
// binary STL its 80-byte header. The readers here honour that and give metres back, so a file without it
// is taken as metres (FIRE's files before units, the reference meshes). glB is always metres and +Y up, as
// glTF 2.0 requires, whatever unit is asked.
enum class LengthUnit : uint8_t { Millimetre, Centimetre, Metre };
inline constexpr LengthUnit kDefaultExportUnit = LengthUnit::Millimetre;
double units_per_metre(LengthUnit unit);  // exact: 1000, 100 or 1
const char* unit_name(LengthUnit unit);
// "mm", "cm" or "m"; an error names the word and the units known.
Result<LengthUnit> length_unit_of(std::string_view name);

// From the file extension, case-insensitive; an error names the path and the extensions known.
Result<SurfaceFormat> surface_format_of(const std::string& path);

// Checks the mesh (vertices and faces present, offsets consistent, faces of 3 or more distinct vertices
// in range, finite coordinates and normals, normals empty or one per vertex) and encodes it. Normals
// missing or of zero length are replaced by the area-weighted normal of the faces around the vertex;
// all normals are written unit length. `source` names the output in messages.
Result<std::string> encode_surface(const SurfaceMesh& surface, SurfaceFormat format, const std::string& source,
                                   LengthUnit unit = kDefaultExportUnit);
// encode_surface for the format of `path`'s extension, then write_file_atomic.
Status write_surface(const SurfaceMesh& surface, const std::string& path, LengthUnit unit = kDefaultExportUnit);

// Positions come back in metres (LengthUnit above); a unit the file names that is not one of ours is an error.
// Reads .obj (through parse_obj; normals are kept when the file has one `vn` per `v`, as written here),
// .ply and .stl in the binary layouts written here, ASCII STL too, and .glb after check_glb. STL has no shared
// vertices: each triangle gets its own three vertices, with the facet normal.
Result<SurfaceMesh> decode_surface(std::string_view bytes, SurfaceFormat format, const std::string& source);
Result<SurfaceMesh> read_surface(const std::string& path);

// What the structural check of a .glb found.
struct GlbSummary {
  uint32_t total_length = 0;  // header's length field (equal to the byte count)
  uint32_t json_length = 0;   // JSON chunk payload, a multiple of 4
  uint32_t bin_length = 0;    // BIN chunk payload, a multiple of 4
  uint32_t vertex_count = 0;
  uint32_t index_count = 0;
  Vec3 position_min = Vec3::Zero(), position_max = Vec3::Zero();  // from the POSITION accessor
};
// Header (magic "glTF", version 2, length equal to the data size), a JSON chunk then a BIN chunk, both
// 4-byte aligned and exactly covering the file; asset.version "2.0"; the buffer fits the BIN chunk; every
// bufferView fits the buffer; every accessor of the mesh primitive fits its bufferView; POSITION min/max
// equal the data's; indices are below the vertex count. Errors name `source` and the failed check.
Result<GlbSummary> check_glb(std::string_view bytes, const std::string& source);

}  // namespace fire
