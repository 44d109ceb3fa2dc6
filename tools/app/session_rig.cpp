#include "tools/app/session_rig.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "platform/files.hpp"
#include "platform/wiimote/roles.hpp"
#include "systems/tracking/rig_io.hpp"

namespace fire {

namespace {

using tracking::CalibrationResult;
using tracking::DeviceStreams;
using tracking::decode_device_streams;
using tracking::rig_from_json;

// An error when the log's cameras are other remotes than the ones the rig was calibrated with.
std::string other_remotes(const DeviceStreams& streams, const std::vector<wiimote::RemoteAssignment>& rig_remotes,
                          const std::string& log_path, const std::string& rig_path) {
  for (int c = 0; c < 2; ++c) {
    if (streams.camera_address[c].empty()) continue;
    const wiimote::Role role = c == 0 ? wiimote::Role::Camera0 : wiimote::Role::Camera1;
    const std::string seen = wiimote::normalize_address(streams.camera_address[c]);
    for (const wiimote::RemoteAssignment& r : rig_remotes)
      if (r.role == role && r.address != seen)
        return log_path + ": camera " + std::to_string(c) + " is the remote " + seen + ", but " + rig_path +
               " was calibrated with " + r.address + " as camera " + std::to_string(c) +
               "; track with the rig of these remotes, or calibrate them (fire calibrate)";
  }
  return "";
}

}  // namespace

Result<TrackingRig> load_tracking_rig(const std::string& rig_path, const InputLog& log, const std::string& log_path) {
  Result<std::string> rig_text = read_text_file(rig_path);
  if (!rig_text) return Result<TrackingRig>::failure(rig_text.error());
  return tracking_rig_from_json(*rig_text, rig_path, log, log_path);
}

Result<TrackingRig> tracking_rig_from_json(const std::string& rig_text, const std::string& rig_path, const InputLog& log,
                                           const std::string& log_path) {
  using R = Result<TrackingRig>;
  Result<CalibrationResult> rig = rig_from_json(rig_text, rig_path);
  if (!rig) return R::failure(rig.error());
  const auto rig_remotes = wiimote::remotes_from_rig_json(rig_text, rig_path);
  if (!rig_remotes) return R::failure(rig_remotes.error());
  const DeviceStreams streams = decode_device_streams(log.events);
  if (const std::string why = other_remotes(streams, *rig_remotes, log_path, rig_path); !why.empty()) return R::failure(why);
  TrackingRig out;
  out.cam0 = rig->cam0;
  out.cam1 = rig->cam1;
  out.time_offset_us = rig->time_offset_us;
  return out;
}

bool has_device_reports(const InputLog& log) {
  return std::any_of(log.events.begin(), log.events.end(), [](const InputEvent& e) { return e.kind == EventKind::Hid; });
}

std::string identified_marks_to_json(const std::vector<IdentifiedMark>& marks, std::string_view frame) {
  nlohmann::ordered_json out = {{"format", "fire-marks"}, {"version", 1}, {"units", "metres"}, {"frame", frame},
                                {"marks", nlohmann::ordered_json::array()}};
  for (const IdentifiedMark& m : marks) out["marks"].push_back({{"id", m.id}, {"x", m.p.x()}, {"y", m.p.y()}, {"z", m.p.z()}});
  return out.dump(2) + "\n";
}

std::string marks_to_json(const std::vector<Vec3>& marks) {
  std::vector<IdentifiedMark> identified;
  for (size_t k = 0; k < marks.size(); ++k) identified.push_back({uint32_t(k), marks[k]});
  return identified_marks_to_json(identified, "object");
}

Result<std::vector<IdentifiedMark>> identified_marks_from_json(std::string_view text, const std::string& source) {
  using R = Result<std::vector<IdentifiedMark>>;
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded()) return R::failure(source + ": not JSON");
  if (!j.is_object() || j.value("format", "") != "fire-marks")
    return R::failure(source + ": not a marks file (\"format\": \"fire-marks\")");
  if (!j.contains("marks") || !j["marks"].is_array() || j["marks"].empty())
    return R::failure(source + ": no \"marks\" array, or an empty one");
  std::vector<IdentifiedMark> marks;
  for (const nlohmann::json& m : j["marks"]) {
    const std::string which = source + ": mark " + std::to_string(marks.size()) + " of the array";
    if (!m.is_object() || !m.contains("id") || !m["id"].is_number_unsigned() || m["id"].get<uint64_t>() > UINT32_MAX)
      return R::failure(which + ": its \"id\" must be a whole number from 0 to " + std::to_string(UINT32_MAX));
    IdentifiedMark& out = marks.emplace_back();
    out.id = m["id"].get<uint32_t>();
    for (size_t k = 0; k + 1 < marks.size(); ++k)
      if (marks[k].id == out.id) return R::failure(which + ": id " + std::to_string(out.id) + " is given twice");
    for (int k = 0; k < 3; ++k) {
      const char* axis = k == 0 ? "x" : k == 1 ? "y" : "z";
      if (!m.contains(axis) || !m[axis].is_number() || !std::isfinite(m[axis].get<double>()))
        return R::failure(which + ": \"" + axis + "\" must be a finite number of metres");
      out.p[k] = m[axis].get<double>();
    }
  }
  return marks;
}

Result<std::vector<Vec3>> marks_from_json(std::string_view text, const std::string& source) {
  using R = Result<std::vector<Vec3>>;
  auto identified = identified_marks_from_json(text, source);
  if (!identified) return R::failure(identified.error());
  std::vector<Vec3> marks;
  for (const IdentifiedMark& m : *identified) {
    if (m.id != marks.size())
      return R::failure(source + ": mark " + std::to_string(marks.size()) + ": its \"id\" must be " + std::to_string(marks.size()) +
                        " (ids run 0, 1, ... in order)");
    marks.push_back(m.p);
  }
  return marks;
}

}  // namespace fire
