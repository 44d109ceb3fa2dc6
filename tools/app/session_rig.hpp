#pragma once
// The rig a session's device reports were drawn with: from a rig file given on the command line, or from
// the copy a session folder keeps (engine/SESSION.md), checked against the log's remotes either way.
#include <string>
#include <string_view>
#include <vector>

#include "engine/input_log.hpp"
#include "systems/triangulate/triangulate.hpp"

namespace fire {

// The rig a log of device reports was drawn with, for the triangulation system: reads rig_path and refuses
// it when the log's device records name other remotes than the rig's. Errors name the files.
Result<TrackingRig> load_tracking_rig(const std::string& rig_path, const InputLog& log, const std::string& log_path);
// The same from rig.json's text (a session folder's copy); `rig_path` names it in errors.
Result<TrackingRig> tracking_rig_from_json(const std::string& rig_text, const std::string& rig_path, const InputLog& log,
                                           const std::string& log_path);
// The marks file (`fire simulate drawing --marks-out`, a session's marks.json): each mark's id and its
// position in the object's frame, metres. Ids run 0, 1, ... in order; errors name `source` and the mark.
std::string marks_to_json(const std::vector<Vec3>& marks);
Result<std::vector<Vec3>> marks_from_json(std::string_view text, const std::string& source);
// The same format where the ids are any distinct numbers, in any order: the marks measured by touch
// (`fire replay --measured-marks-out`), a subset of the object's, matched with its marks file by id.
struct IdentifiedMark {
  uint32_t id = 0;
  Vec3 p = Vec3::Zero();
};
std::string identified_marks_to_json(const std::vector<IdentifiedMark>& marks, std::string_view frame);
Result<std::vector<IdentifiedMark>> identified_marks_from_json(std::string_view text, const std::string& source);
// Whether a log holds device reports (and so needs a rig to be replayed).
bool has_device_reports(const InputLog& log);

}  // namespace fire
