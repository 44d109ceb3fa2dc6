#include "platform/network_file.hpp"

#include "engine/network_io.hpp"
#include "platform/files.hpp"

namespace fire {

Status save_network(const Mesh& mesh, const std::string& path) {
  Mesh compact = mesh;
  compact.compact();
  return write_file_atomic(path, network_to_json(compact));
}

Result<Mesh> load_network(const std::string& path) {
  auto text = read_text_file(path);
  if (!text) return Result<Mesh>::failure(text.error());
  if (text->empty()) return Result<Mesh>::failure(path + ": empty file (expected a FIRE curve network)");
  return network_from_json(*text, path);
}

Status export_network_obj(const Mesh& mesh, const std::string& path) {
  return write_file_atomic(path, network_to_obj(mesh));
}

}  // namespace fire
