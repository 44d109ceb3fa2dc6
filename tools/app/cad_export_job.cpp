#include "tools/app/cad_export_job.hpp"

#include <chrono>
#include <utility>

#include "platform/cad/cad_export.hpp"
#include "systems/catmull_clark/bspline_patches.hpp"

namespace fire {

namespace {

std::string write_cad_file(const Cage& cage, const std::string& path, LengthUnit unit) {
  auto converted = catmull_clark::bspline_patches(cage);
  if (!converted) return "export failed: " + path + ": " + converted.error();
  auto written = cad::write_cad(converted->patches, path, unit);
  if (!written) return "export failed: " + written.error();
  return "exported " + std::to_string(written->faces) + " B-spline patches (" + std::to_string(converted->exact) + " exact, " +
         std::to_string(converted->fitted) + " fitted) to " + path + (written->solids ? " as a solid" : "");
}

}  // namespace

bool is_cad_path(const std::string& path) { return cad::cad_format_of(path).ok(); }

CadExportJob::~CadExportJob() {
  if (result_.valid()) result_.wait();
}

bool CadExportJob::start(Cage cage, std::string path, LengthUnit unit) {
  if (running()) return false;
  result_ = std::async(std::launch::async, [cage = std::move(cage), path = std::move(path), unit] {
    return write_cad_file(cage, path, unit);
  });
  return true;
}

std::optional<std::string> CadExportJob::finished() {
  if (!result_.valid() || result_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return std::nullopt;
  return result_.get();
}

std::optional<std::string> CadExportJob::wait() {
  if (!result_.valid()) return std::nullopt;
  return result_.get();
}

}  // namespace fire
