#include "systems/tracking/rig_io.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <nlohmann/json.hpp>

namespace fire::tracking {
namespace {

using nlohmann::json;

json camera_to_json(const Camera& c) {
  json R = json::array();
  for (int r = 0; r < 3; ++r) R.push_back({c.R(r, 0), c.R(r, 1), c.R(r, 2)});
  return {{"intrinsics",
           {{"fx", c.K.fx}, {"fy", c.K.fy}, {"cx", c.K.cx}, {"cy", c.K.cy}, {"k1", c.K.k1}, {"k2", c.K.k2}}},
          {"R", R},
          {"t", {c.t.x(), c.t.y(), c.t.z()}}};
}

// Reads one member as a finite number; `where` names it in the message.
Result<double> number(const json& object, const char* key, const std::string& where) {
  if (!object.is_object() || !object.contains(key))
    return Result<double>::failure(where + ": missing \"" + key + "\"");
  const json& v = object.at(key);
  if (!v.is_number()) return Result<double>::failure(where + "." + key + ": not a number");
  const double d = v.get<double>();
  if (!std::isfinite(d)) return Result<double>::failure(where + "." + key + ": not finite");
  return d;
}

Result<double> element(const json& array, size_t i, const std::string& where) {
  const json& v = array.at(i);
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    return Result<double>::failure(where + "[" + std::to_string(i) + "]: not a finite number");
  return v.get<double>();
}

Result<Camera> camera_from_json(const json& j, const std::string& where) {
  using R = Result<Camera>;
  if (!j.is_object()) return R::failure(where + ": not an object");
  if (!j.contains("intrinsics")) return R::failure(where + ": missing \"intrinsics\"");
  const json& k = j.at("intrinsics");
  const std::string kw = where + ".intrinsics";
  Camera c;
  double* fields[] = {&c.K.fx, &c.K.fy, &c.K.cx, &c.K.cy, &c.K.k1, &c.K.k2};
  const char* names[] = {"fx", "fy", "cx", "cy", "k1", "k2"};
  for (int i = 0; i < 6; ++i) {
    const Result<double> v = number(k, names[i], kw);
    if (!v) return R::failure(v.error());
    *fields[i] = *v;
  }
  if (!(c.K.fx > 0) || !(c.K.fy > 0)) return R::failure(kw + ": focal lengths must be positive");

  if (!j.contains("R") || !j.at("R").is_array() || j.at("R").size() != 3)
    return R::failure(where + ".R: expected 3 rows");
  for (size_t r = 0; r < 3; ++r) {
    const json& row = j.at("R").at(r);
    const std::string rw = where + ".R[" + std::to_string(r) + "]";
    if (!row.is_array() || row.size() != 3) return R::failure(rw + ": expected 3 numbers");
    for (size_t col = 0; col < 3; ++col) {
      const Result<double> v = element(row, col, rw);
      if (!v) return R::failure(v.error());
      c.R(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(col)) = *v;
    }
  }
  if ((c.R.transpose() * c.R - Eigen::Matrix3d::Identity()).norm() > 1e-6 || c.R.determinant() < 0)
    return R::failure(where + ".R: not a rotation matrix");

  if (!j.contains("t") || !j.at("t").is_array() || j.at("t").size() != 3)
    return R::failure(where + ".t: expected 3 numbers");
  for (size_t i = 0; i < 3; ++i) {
    const Result<double> v = element(j.at("t"), i, where + ".t");
    if (!v) return R::failure(v.error());
    c.t(static_cast<Eigen::Index>(i)) = *v;
  }
  return c;
}

}  // namespace

std::string rig_to_json(const CalibrationResult& rig) {
  // nlohmann writes the shortest decimal that reads back to the same double.
  const json j = {{"format", "fire-rig"},
                  {"version", 1},
                  {"units", "metres, pixels"},
                  {"cameras", {camera_to_json(rig.cam0), camera_to_json(rig.cam1)}},
                  {"calibration",
                   {{"reprojection_rms_px", rig.reprojection_rms_px},
                    {"reprojection_rms_2d_px", rig.reprojection_rms_2d_px},
                    {"wand_length_error_mm", rig.wand_length_error_mm},
                    {"time_offset_ms", rig.time_offset_us * 1e-3},
                    {"observations_used", rig.observations_used},
                    {"observations_rejected", rig.observations_rejected},
                    {"iterations", rig.iterations}}}};
  return j.dump(2) + "\n";
}

Result<CalibrationResult> rig_from_json(std::string_view text, const std::string& source) {
  using R = Result<CalibrationResult>;
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return R::failure(source + ": not valid JSON");
  if (!j.is_object()) return R::failure(source + ": expected a JSON object");
  if (!j.contains("format") || j.at("format") != "fire-rig")
    return R::failure(source + ": not a rig file (\"format\" must be \"fire-rig\")");
  if (!j.contains("version") || !j.at("version").is_number_integer())
    return R::failure(source + ": missing integer \"version\"");
  if (j.at("version").get<int64_t>() != 1)
    return R::failure(source + ": rig format version " + j.at("version").dump() +
                      " is not supported (this build reads version 1)");
  if (!j.contains("cameras") || !j.at("cameras").is_array() || j.at("cameras").size() != 2)
    return R::failure(source + ": \"cameras\" must be an array of 2 cameras");
  CalibrationResult rig;
  Camera* cams[] = {&rig.cam0, &rig.cam1};
  for (size_t i = 0; i < 2; ++i) {
    Result<Camera> c = camera_from_json(j.at("cameras").at(i), source + ": cameras[" + std::to_string(i) + "]");
    if (!c) return R::failure(c.error());
    *cams[i] = *c;
  }
  if (!j.contains("calibration") || !j.at("calibration").is_object())
    return R::failure(source + ": missing \"calibration\" object");
  const json& cal = j.at("calibration");
  const std::string cw = source + ": calibration";
  double* stats[] = {&rig.reprojection_rms_px, &rig.reprojection_rms_2d_px, &rig.wand_length_error_mm};
  const char* stat_names[] = {"reprojection_rms_px", "reprojection_rms_2d_px", "wand_length_error_mm"};
  for (int i = 0; i < 3; ++i) {
    const Result<double> v = number(cal, stat_names[i], cw);
    if (!v) return R::failure(v.error());
    *stats[i] = *v;
  }
  if (cal.contains("time_offset_ms")) {  // absent from rigs written before it was kept
    const Result<double> v = number(cal, "time_offset_ms", cw);
    if (!v) return R::failure(v.error());
    if (!(std::abs(*v) < 1e6)) return R::failure(cw + ".time_offset_ms: out of range");
    rig.time_offset_us = *v * 1e3;
  }
  int* counts[] = {&rig.observations_used, &rig.observations_rejected, &rig.iterations};
  const char* count_names[] = {"observations_used", "observations_rejected", "iterations"};
  for (int i = 0; i < 3; ++i) {
    if (!cal.contains(count_names[i]) || !cal.at(count_names[i]).is_number_integer())
      return R::failure(cw + "." + count_names[i] + ": missing or not an integer");
    const int64_t v = cal.at(count_names[i]).get<int64_t>();
    if (v < 0 || v > 1'000'000'000) return R::failure(cw + "." + count_names[i] + ": out of range");
    *counts[i] = static_cast<int>(v);
  }
  return rig;
}

}  // namespace fire::tracking
