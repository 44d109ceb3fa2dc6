// The CAD export in a build without OpenCASCADE: every call says so.
#include "platform/cad/cad_export.hpp"

namespace fire::cad {
namespace {
std::string unavailable(const std::string& path) {
  return path + ": FIRE was built without OpenCASCADE, so it cannot write or read STEP and IGES (install the "
                "libocct-*-dev packages, as tools/run does, and build again)";
}
}  // namespace

bool cad_available() { return false; }

Result<CadWritten> write_cad(const BsplinePatches&, const std::string& path, LengthUnit) {
  return Result<CadWritten>::failure(unavailable(path));
}

Result<CadShapeInfo> read_cad(const std::string& path, uint32_t) {
  return Result<CadShapeInfo>::failure(unavailable(path));
}

}  // namespace fire::cad
