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

}  // namespace fire
