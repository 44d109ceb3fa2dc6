// GLB surface reader (decode_surface with SurfaceFormat::Glb); properties in fuzz_surface.hpp.
#include "tests/fuzz/fuzz_surface.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fire::fuzz::fuzz_surface(data, size, fire::SurfaceFormat::Glb);
}
