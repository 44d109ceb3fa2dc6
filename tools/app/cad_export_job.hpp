#pragma once
// The app's E for STEP and IGES: converting the limit surface to B-spline patches and sewing them through
// OpenCASCADE take seconds on a whole object, so it runs on a worker thread while the frame loop goes on. The
// cage is copied when E is pressed; what is drawn after that is not in the file.
#include <future>
#include <optional>
#include <string>

#include "engine/cage.hpp"
#include "platform/surface_io.hpp"

namespace fire {

class CadExportJob {
 public:
  CadExportJob() = default;
  CadExportJob(const CadExportJob&) = delete;
  CadExportJob& operator=(const CadExportJob&) = delete;
  ~CadExportJob();  // waits for a file being written: no export is lost on exit

  bool running() const { return result_.valid(); }
  // Starts writing `cage`'s surface to `path` (.step, .stp, .igs, .iges) in `unit`; false if one is running.
  bool start(Cage cage, std::string path, LengthUnit unit);
  // What the finished job wrote, or why it failed, once; nothing while it runs or when none ran.
  std::optional<std::string> finished();
  // The same, waiting for a job still running.
  std::optional<std::string> wait();

 private:
  std::future<std::string> result_;
};

// Whether `path` names a CAD format (.step, .stp, .igs, .iges, any case).
bool is_cad_path(const std::string& path);

}  // namespace fire
