// Network file reader (network_from_json, what load_network runs on a file's text): a failed parse
// names the input and the problem; a parsed network passes Mesh::validate and its JSON reads back to
// the same network, written the same way.
#include <cstdint>
#include <string_view>

#include "engine/network_io.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace fire;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const Result<Mesh> mesh = network_from_json(text, fuzz::kSource);
  if (!mesh) {
    FUZZ_CHECK(fuzz::names_input_and_problem(mesh.error()), "an error names the input and the problem");
    return 0;
  }
  FUZZ_CHECK(mesh->validate().empty(), "a parsed network is valid");
  for (VertexIndex v{0}; v < mesh->vertex_slots(); ++v)
    FUZZ_CHECK(mesh->vertices.position[v].allFinite(), "vertex positions are finite");
  const std::string written = network_to_json(*mesh);
  const Result<Mesh> again = network_from_json(written, fuzz::kSource);
  FUZZ_CHECK(again.ok(), "a written network parses");
  FUZZ_CHECK(network_to_json(*again) == written, "parse -> write -> parse keeps the network");
  return 0;
}
