// What the CAD export knows with or without OpenCASCADE: the formats by extension.
#include "platform/cad/cad_export.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace fire::cad {

Result<CadFormat> cad_format_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".step" || ext == ".stp") return CadFormat::step;
  if (ext == ".igs" || ext == ".iges") return CadFormat::iges;
  return Result<CadFormat>::failure(path + ": not a CAD file name (.step, .stp, .igs or .iges)");
}

}  // namespace fire::cad
