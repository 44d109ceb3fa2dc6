// Rig file reader (rig_from_json): a failed parse names the input and the problem; a parsed rig has
// finite intrinsics with positive focal lengths, rotation matrices, and reads back bit for bit after
// rig_to_json.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string_view>

#include <Eigen/Dense>

#include "systems/tracking/rig_io.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace fire;
using namespace fire::tracking;

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool same_camera(const Camera& a, const Camera& b) {
  const double ka[] = {a.K.fx, a.K.fy, a.K.cx, a.K.cy, a.K.k1, a.K.k2};
  const double kb[] = {b.K.fx, b.K.fy, b.K.cx, b.K.cy, b.K.k1, b.K.k2};
  for (int i = 0; i < 6; ++i)
    if (!same_bits(ka[i], kb[i])) return false;
  for (int i = 0; i < 9; ++i)
    if (!same_bits(a.R.data()[i], b.R.data()[i])) return false;
  for (int i = 0; i < 3; ++i)
    if (!same_bits(a.t[i], b.t[i])) return false;
  return true;
}

void check_camera(const Camera& c) {
  const double k[] = {c.K.fx, c.K.fy, c.K.cx, c.K.cy, c.K.k1, c.K.k2};
  for (double v : k) FUZZ_CHECK(std::isfinite(v), "intrinsics are finite");
  FUZZ_CHECK(c.K.fx > 0 && c.K.fy > 0, "focal lengths are positive");
  FUZZ_CHECK(c.R.allFinite() && c.t.allFinite(), "pose is finite");
  FUZZ_CHECK((c.R.transpose() * c.R - Eigen::Matrix3d::Identity()).norm() <= 1e-6 && c.R.determinant() >= 0,
             "R is a rotation");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const Result<CalibrationResult> rig = rig_from_json(text, fuzz::kSource);
  if (!rig) {
    FUZZ_CHECK(fuzz::names_input_and_problem(rig.error()), "an error names the input and the problem");
    return 0;
  }
  check_camera(rig->cam0);
  check_camera(rig->cam1);
  FUZZ_CHECK(std::isfinite(rig->reprojection_rms_px) && std::isfinite(rig->reprojection_rms_2d_px) &&
                 std::isfinite(rig->wand_length_error_mm),
             "calibration figures are finite");
  FUZZ_CHECK(rig->observations_used >= 0 && rig->observations_rejected >= 0 && rig->iterations >= 0,
             "calibration counts are not negative");
  const Result<CalibrationResult> again = rig_from_json(rig_to_json(*rig), fuzz::kSource);
  FUZZ_CHECK(again.ok(), "a written rig parses");
  FUZZ_CHECK(same_camera(rig->cam0, again->cam0) && same_camera(rig->cam1, again->cam1),
             "parse -> write -> parse keeps both cameras bit for bit");
  FUZZ_CHECK(same_bits(rig->reprojection_rms_px, again->reprojection_rms_px) &&
                 same_bits(rig->reprojection_rms_2d_px, again->reprojection_rms_2d_px) &&
                 same_bits(rig->wand_length_error_mm, again->wand_length_error_mm) &&
                 rig->observations_used == again->observations_used &&
                 rig->observations_rejected == again->observations_rejected && rig->iterations == again->iterations,
             "parse -> write -> parse keeps the calibration figures");
  return 0;
}
