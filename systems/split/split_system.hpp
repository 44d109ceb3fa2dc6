#pragma once
// The split system: applies this frame's edit requests to the mesh, with undo history.
#include <vector>

#include "engine/mesh.hpp"
#include "systems/split/edit.hpp"

namespace fire {

// Applies requests in order; a rejected one is recorded with its reason and changes nothing.
void split_system(const std::vector<EditRequest>& requests, Mesh& mesh, EditHistory& history,
                  std::vector<Rejection>& rejections);

}  // namespace fire
