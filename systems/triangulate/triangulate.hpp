#pragma once
// The triangulation system: from the remotes' IR reports to pen samples and pen down/up, one frame at a
// time, seeing only the reports that have arrived before the frame ends (no look-ahead).
//
// Per camera it keeps a trailing window of reports: each report's instant on the remote's own frame clock
// (a line through the trailing reports' frame numbers and arrival times at the session's rate, once the 5
// reports after it have settled its number), and the blob links between consecutive reports. A camera 0 report
// is triangulated once camera 1 has a report after its instant (camera 1's blobs are interpolated to it),
// or once camera 1 has been silent too long to have one. The offset between the two remotes' latencies
// starts at the rig file's value and is re-estimated every few seconds from the moving blobs of the
// trailing window, since it changes on every reconnect. The pen's strokes follow the same rules as
// `fire track` always had: see tracking::PenTrackOptions; `fire track` is a loop over this system.
#include <array>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "engine/input_log.hpp"
#include "engine/scheduler.hpp"
#include "engine/session_dir.hpp"
#include "systems/tracking/track.hpp"

namespace fire {

using tracking::Vec2;

// The calibrated rig as the system reads it (from rig.json and the command line).
struct TrackingRig {
  tracking::Camera cam0, cam1;          // cam0 at the origin; metres
  double time_offset_us = 0;            // camera 1's latency minus camera 0's: where the estimate starts
  bool estimate_time_offset = true;     // false: time_offset_us is used as it is throughout
  tracking::PenTrackOptions options;
};

// One camera's trailing reports. `frames` holds the reports whose instant is fixed, oldest first;
// `first_index` is the index of frames[0] among all the camera's reports.
struct CameraWindow {
  tracking::CameraFrames frames;
  tracking::BlobLinks links;  // links[k]: frames[k] to frames[k + 1] (all -1 for the newest)
  uint64_t first_index = 0;
  // The newest reports, whose frame numbers the next ones may still change (a late report looks like one
  // after a lost report until the reports after it show otherwise).
  std::deque<tracking::CameraReport> waiting;
  // Frame clock: recent arrival gaps (for the period and the timeouts), the frame numbering.
  std::deque<double> gaps_us;
  double period_us = kReportPeriodUs;                // their median once there are 8 (the nominal 100 Hz before)
  int64_t origin_us = 0;                      // arrival time of the camera's first report
  tracking::FrameNumbering clock;             // on arrivals since origin_us
  int64_t last_arrival_us = 0;
  uint64_t reports = 0;                       // reports taken (not out of order)

  uint64_t end_index() const { return first_index + frames.size(); }
};

struct TriangulateState {
  tracking::DeviceDecoder decoder;
  std::array<CameraWindow, 2> cameras;
  size_t out_of_order = 0;       // reports that arrived earlier than their camera's previous one: dropped
  size_t duplicated = 0;         // reports equal to their camera's previous one, at the same instant (kept)
  size_t both_lost = 0;          // times neither camera saw the pen in the middle of a stroke that went on after
  bool lost_now = false;
  size_t stray_frames = 0;       // pen samples taken from a frame that also showed another blob (a reflection)
  std::array<size_t, 2> silences{};  // times each camera stopped reporting for more than half a second
  std::array<bool, 2> silent{};      // ... and is silent now
  uint64_t next_cam0 = 0;        // index of the next camera 0 report to triangulate
  // Time offset: the value in use, and the moving camera 0 blobs it is re-estimated from.
  double time_offset_us = 0;
  bool time_offset_started = false;
  std::deque<tracking::MovingBlob> moving;
  uint64_t cam0_fixed = 0;       // camera 0 reports whose instant is fixed, for the estimation schedule
  uint64_t offset_attempts = 0;  // estimates made (one per kOffsetEvery camera 0 reports)
  int offset_estimates = 0;      // of those, observable ones, adopted
  tracking::TimeOffsetEstimate last_estimate;
  // The pen.
  tracking::PenCounts counts;
  bool down = false;
  bool stroke_open = false;      // a Down has been emitted for the current stroke
  tracking::OneEuroState filter;
  double last_sample_t = 0, last_seen_t = 0;
  int64_t last_sample_t_us = 0;
  uint32_t last_sample_line = 0;
  Vec3 last_position = Vec3::Zero();
  std::array<Vec2, 2> pen_px{Vec2::Zero(), Vec2::Zero()};

  // Reports still waiting (for their clock, or for the other camera) or a stroke still open: a replay
  // that has run out of events keeps running frames until this is false.
  bool busy() const;
};

// Reads the frame's `hid` and `meta device` events from `frame_events` and writes to `pen_events` (cleared
// first) the pen's Down, Pen and Up events (filtered positions, the rig's frame, metres), each stamped with
// its sample's instant. `samples`, when given, receives every pen sample too (what `fire track --truth`
// measures).
void triangulate_system(const FrameTime& frame, const TrackingRig& rig, const std::vector<InputEvent>& frame_events,
                        TriangulateState& state, std::vector<InputEvent>& pen_events,
                        std::vector<tracking::PenSample>* samples = nullptr);

// For snapshots (engine/SESSION.md): every field, so a reopened session triangulates its log's tail as the
// run that wrote the snapshot would have. Loading fails on a state that cannot be (sizes that disagree).
void save_triangulate_state(SnapshotWriter& out, const TriangulateState& state);
bool load_triangulate_state(SnapshotReader& in, TriangulateState& state);

// What went wrong with the device input so far, one sentence per kind of problem (none: empty).
std::vector<std::string> describe_device_problems(const TriangulateState& state);

// The two halves of triangulate_system, for reports that do not come from a log (exact pixels in tests):
// takes one report, then triangulates what the reports taken so far allow at `now_us` (the frame's end).
void triangulate_report(const TrackingRig& rig, TriangulateState& state, const tracking::CameraReport& report);
void triangulate_advance(int64_t now_us, const TrackingRig& rig, TriangulateState& state, std::vector<InputEvent>& pen_events,
                         std::vector<tracking::PenSample>* samples);

// `fire track`: the system over the whole log, frame by frame, until it is no longer busy. The pen events
// are the system's (not shaped); `track` receives the samples and counts.
std::vector<InputEvent> track_log(std::span<const InputEvent> events, const TrackingRig& rig, tracking::PenTrack& track,
                                  TriangulateState* final_state = nullptr);

}  // namespace fire
