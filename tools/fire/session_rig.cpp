#include "tools/fire/session_rig.hpp"

#include <algorithm>

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

}  // namespace fire
