#pragma once
// Curve network files on disk (format: engine/NETWORK_FORMAT.md).
#include <string>

#include "engine/mesh.hpp"

namespace fire {

// Writes a copy of the mesh, compacted, atomically.
Status save_network(const Mesh& mesh, const std::string& path);
Result<Mesh> load_network(const std::string& path);
// The network's polylines as OBJ lines, written atomically.
Status export_network_obj(const Mesh& mesh, const std::string& path);

}  // namespace fire
