#pragma once
// The curve network file (format in engine/NETWORK_FORMAT.md): the polyline mesh as JSON.
#include <string>
#include <string_view>

#include "engine/mesh.hpp"

namespace fire {

// Writes a compact mesh (no tombstones: call Mesh::compact first). Doubles are written so that they read
// back bit for bit.
std::string network_to_json(const Mesh& mesh);
// Parses and validates a network; errors name `source` and the problem. The result equals the compact
// mesh that was written, pool for pool.
Result<Mesh> network_from_json(std::string_view text, const std::string& source);

// The network's polylines as OBJ: a `v` per polyline point (vertices shared), an `l` per edge.
std::string network_to_obj(const Mesh& mesh);

}  // namespace fire
