#include "systems/split/split_system.hpp"

namespace fire {

void split_system(const std::vector<EditRequest>& requests, Mesh& mesh, EditHistory& history,
                  std::vector<Rejection>& rejections) {
  for (const EditRequest& r : requests) {
    Status outcome = r.kind == RequestKind::Undo   ? history.undo(mesh)
                          : r.kind == RequestKind::Redo ? history.redo(mesh)
                                                        : history.apply(mesh, r.command);
    if (!outcome.ok()) rejections.push_back({r.t_us, r.line, outcome.error});
  }
}

}  // namespace fire
