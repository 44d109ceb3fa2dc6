#include "platform/network_file.hpp"

#include <cctype>

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
  // OBJ text under another format's name would be read as that format, and fail there.
  const size_t dot = path.find_last_of('.'), slash = path.find_last_of('/');
  std::string extension = dot == std::string::npos || (slash != std::string::npos && dot < slash) ? "" : path.substr(dot + 1);
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension != "obj")
    return Status::failure(path + ": the network's polylines are written as OBJ lines; give a name ending in .obj");
  return write_file_atomic(path, network_to_obj(mesh));
}

}  // namespace fire
