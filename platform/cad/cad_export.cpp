// What the CAD export knows with or without OpenCASCADE: the formats by extension.
#include "platform/cad/cad_export.hpp"

#include "platform/files.hpp"

namespace fire::cad {

Result<CadFormat> cad_format_of(const std::string& path) {
  const std::string ext = file_extension(path);
  if (ext == "step" || ext == "stp") return CadFormat::Step;
  if (ext == "igs" || ext == "iges") return CadFormat::Iges;
  return Result<CadFormat>::failure(path + ": not a CAD file name (.step, .stp, .igs or .iges)");
}

}  // namespace fire::cad
