#pragma once
// Wavefront OBJ polygon meshes: `v` and `f` lines (f accepts v, v/vt, v//vn, v/vt/vn and negative indices);
// every other statement is ignored, except FIRE's `# units: mm` comment (platform/surface_io.hpp's LengthUnit):
// positions come back in metres. Errors name the file, the line and the problem.
#include <string>
#include <string_view>

#include "engine/common.hpp"
#include "engine/polygon_mesh.hpp"

namespace fire {

// Parses OBJ text; `source` names it in messages. Rejects: no vertices or faces, non-finite coordinates,
// faces with fewer than 3 vertices, indices out of range, a vertex repeated within one face.
Result<PolygonMesh> parse_obj(std::string_view text, const std::string& source);
Result<PolygonMesh> read_obj(const std::string& path);

// Per vertex, 1 where it lies on the mesh's border (an end of an edge one face alone uses).
std::vector<uint8_t> border_vertices(const PolygonMesh& mesh);

// OpenSubdiv's subdivision tags in an OBJ (its regression shapes', and `fire reconstruct --cage`'s), as FIRE's
// Catmull-Clark takes them: `t crease 2/1/0 A B S` and `t corner 1/1/0 V S` with vertex indices from 0 and S
// at least 10 (infinitely sharp), `t interpolateboundary 1/0/0 K` with K 1 (EdgeAndCorner, the default) or 2
// (EdgeOnly). Anything FIRE's subdivision cannot honour (a finite sharpness, a corner off the border, another
// boundary rule, another tag) is an error naming the line, never ignored.
struct SubdivisionTags {
  std::vector<uint32_t> sharp_edges;    // vertex pairs
  std::vector<uint8_t> border_corners;  // per vertex; empty for EdgeAndCorner without `t corner`
};
Result<SubdivisionTags> parse_obj_tags(std::string_view text, const std::string& source, const PolygonMesh& mesh);

}  // namespace fire
