#pragma once
// From logged device reports to what the engine consumes: pen samples with down/up, and the
// time-aligned wand observations that calibration needs.
//
// Time. The two remotes are not synchronized and their reports carry no timestamps; each report
// is logged when it reaches the host. Per camera, the remote's regular frame clock is recovered
// from those arrival times (fit_frame_clock). What no timestamp shows is the difference of the
// two cameras' latencies; it is estimated from the geometry (estimate_time_offset): moving blobs
// only satisfy the epipolar constraint when camera 1's track is read at the right instant.
// Camera 1's blob tracks are then interpolated to camera 0's instants before triangulating.
#include <array>
#include <map>
#include <string>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <vector>

#include "engine/camera.hpp"
#include "engine/common.hpp"
#include "engine/input_log.hpp"
#include "engine/ir_report.hpp"
#include "engine/session_dir.hpp"
#include "systems/tracking/calibration.hpp"
#include "systems/tracking/signal.hpp"
#include "systems/tracking/triangulation.hpp"

namespace fire::tracking {

// Per-category counts of what a stream of reports held.
struct ReportCounts {
  size_t ir_reports = 0;          // decoded IR reports (0x33, 0x36, 0x37)
  size_t not_ir = 0;              // valid reports without IR data, skipped
  size_t garbled = 0;             // hex that did not parse, or no bytes at all
  size_t bad_length = 0;          // truncated IR reports
  size_t unknown_id = 0;          // report ids no Wii Remote sends
  size_t unknown_device = 0;      // devices that are no camera: not 0 or 1 in a log without device records,
                                  // or with no camera role in the log's `meta device` records
  size_t pad_reports = 0;         // reports of the command pad (role `pad` in `meta device`): no camera data
  size_t bad_device_records = 0;  // `meta device` records that do not read as D ADDRESS ROLE PRODUCT, or whose
                                  // product is no Wii Remote's (0306, 0330): their device is no camera
  size_t out_of_range_slots = 0;  // blobs with impossible coordinates, dropped from kept reports
  size_t rejected_reports() const { return garbled + bad_length + unknown_id + unknown_device; }
};

// The IR reports of one camera, one entry per report (structure of arrays).
struct CameraFrames {
  std::vector<int64_t> t_us;       // host arrival time, as logged (the key to the report's line)
  std::vector<uint32_t> line;      // the report's line in the log (0: not from a file)
  std::vector<double> t_frame_us;  // the remote's frame clock on the host's time axis (fit_frame_clock)
  std::vector<uint8_t> blob_count;
  std::vector<std::array<Vec2, kIrSlots>> blobs;  // the seen blobs first, in slot order
  size_t size() const { return t_us.size(); }
};

struct DeviceStreams {
  std::array<CameraFrames, 2> cameras;
  // The Bluetooth address of each camera's remote, from the log's `meta device` records; empty when
  // the log does not say (simulated sessions). A camera whose remote changed mid-log keeps the first.
  std::array<std::string, 2> camera_address;
  std::string pad_address;
  ReportCounts counts;
};

// One camera's IR report as the systems use it.
struct CameraReport {
  int camera = 0;
  int64_t t_us = 0;  // host arrival time, as logged
  uint32_t line = 0; // in the log (0: not from a file)
  uint8_t blob_count = 0;
  std::array<Vec2, kIrSlots> blobs;  // the seen blobs first, in slot order
};

// Reads logged events one at a time. Which device is which camera comes from the log's `meta device`
// records (D ADDRESS ROLE PRODUCT, roles camera0, camera1, pad), in log order; a log without them (the
// simulator's) has cameras 0 and 1 as devices 0 and 1. Garbled, truncated, unknown and out-of-range input
// is counted in `counts` and skipped, never fatal.
struct DeviceDecoder {
  ReportCounts counts;
  // The Bluetooth address of each camera's remote, from the device records; empty when the log does not
  // say. A camera whose remote changed mid-log keeps the first.
  std::array<std::string, 2> camera_address;
  std::string pad_address;

  // A camera's IR report, or nothing (a record, another kind of event, or input counted and skipped).
  std::optional<CameraReport> read(const InputEvent& event);

  // For snapshots (engine/SESSION.md): everything above and the roles learned from the device records.
  void save(SnapshotWriter& out) const;
  bool load(SnapshotReader& in);

 private:
  std::map<int, int> role_of_;  // device -> camera index or pad, once the log has device records
  bool has_records_ = false;
};

// Decodes every camera's `hid` events (DeviceDecoder). t_frame_us starts as the arrival time.
DeviceStreams decode_device_streams(std::span<const InputEvent> events);

// A remote's frame numbers from the arrival times of its reports, one report at a time. Each report is
// one frame after the one before unless reports were lost in between, and a lost report is rare; so the
// oldest of the reports still waiting gets the number of the most likely numbering of them all (Viterbi:
// misfits to the clock's line in units of the measured jitter, plus -log 1 % per lost report). A late or
// early report is then one outlier, not a shift of the clock. The line runs through the trailing reports
// at the rate of every report so far (the nominal 100 Hz for the first 200), so a miscount cannot tilt it.
// Arrivals are microseconds from any fixed origin (keep them small: they are doubles).
struct FrameNumbering {
  static constexpr size_t kLookahead = 5;  // reports after the oldest that settle its number

  // Settles the number of waiting[0], given the reports after it (up to kLookahead are used) and the
  // arrival of the report settled before it (NaN: none), records it and returns it. The first report is
  // number 0.
  double settle(std::span<const double> waiting, double previous_arrival);
  // The clock's instant of frame `number`, on the arrivals' axis.
  double instant(double number) const;

  // The clock's line through the trailing reports' means at the session's rate.
  struct Line {
    double mean_n = 0, mean_t = 0, slope = 0;
    double at(double number) const { return mean_t + slope * (number - mean_n); }
  };
  Line line() const;

  std::deque<std::array<double, 2>> trailing;  // (number, arrival) of the last 400 settled reports
  double count = 0, mean_n = 0, mean_t = 0, cnn = 0, cnt = 0;  // running moments of every settled report
  std::deque<double> residuals;               // |arrival - line| of the last 101: the jitter

 private:
  double record(double number, double arrival);
};

// Replaces arrival jitter by the remote's regular clock: frame numbers as FrameNumbering settles
// them (as the live triangulation system does), then each report's instant read off a least-squares
// line through (frame number, arrival time) over its neighbours on both sides.
void fit_frame_clock(CameraFrames& frames);

// Drops blobs that stay within `radius_px` of where they are for `min_frames` consecutive
// frames: stray reflections and lamps stand still, a waved wand does not. For wand logs only
// (a pen rests on purpose). Returns the number of blobs dropped.
size_t remove_static_blobs(CameraFrames& frames, double radius_px = 2.5, int min_frames = 50);

struct TimeOffsetEstimate {
  double offset_us = 0;         // camera 1 logs an instant this much later than camera 0 does
  double cost_px = 0;           // mean capped epipolar distance at the offset
  double cost_at_zero_px = 0;   // the same with no offset
  size_t samples = 0;           // moving camera 0 blobs that entered the cost
  bool observable = false;      // the cost has a clear minimum (the blobs moved enough)
};

// Searches offsets within +-search_us for the one that makes moving blobs fit the rig's
// epipolar geometry best, each camera 0 blob against the nearest interpolated camera 1 blob.
TimeOffsetEstimate estimate_time_offset(const DeviceStreams& streams, const Camera& c0, const Camera& c1,
                                        double search_us = 50000);

// --- calibration data ---

struct WandExtraction {
  std::vector<WandObservation> observations;
  size_t frames = 0;          // camera 0 frames
  size_t not_two_blobs = 0;   // camera 0 frames without exactly two blobs
  size_t no_partner = 0;      // camera 1 could not be interpolated to the instant with two tracked blobs
};

// One observation per camera 0 frame that shows exactly the two LEDs while camera 1 shows them
// in the frames just before and after its instant (+ cam1_offset_us): camera 1's blobs are
// matched between those frames and interpolated. Frames with a third blob are skipped: run
// remove_static_blobs first so a stray reflection costs nothing.
WandExtraction extract_wand_observations(const DeviceStreams& streams, double cam1_offset_us);

struct WandCalibration {
  CalibrationResult rig;
  double time_offset_used_us = 0;  // the offset the final calibration's observations used
  TimeOffsetEstimate time_offset;   // estimated from the final rig
  int calibrations = 0;        // rounds of calibration with a refined time offset
  WandExtraction extraction;   // of the last round
  size_t static_blobs_removed = 0;
};

// The whole pipeline for a wand log: frame clocks, stray blobs, observations, calibration;
// then the time offset from the calibrated rig and calibration again until it settles.
// options.on_iteration sees every round's bundle adjustment, each starting at iteration 0.
Result<WandCalibration> calibrate_wand_streams(DeviceStreams streams, const CalibrationOptions& options);

// --- what the live triangulation system (systems/triangulate) shares with calibration ---

// For each frame, the blob of the next frame each of its blobs continues as (-1: none).
using BlobLinks = std::vector<std::array<int8_t, kIrSlots>>;
// Frame k's links to frame k + 1: a match is mutual, within the gate, and clearly nearer than any other
// candidate. All -1 for the last frame.
std::array<int8_t, kIrSlots> link_to_next(const CameraFrames& frames, size_t k);
// Typical spacing of a camera's frames on its fitted clock (median).
double frame_period_us(const CameraFrames& frames);
// Interpolating across one lost report, not across more.
inline constexpr double kMaxInterpolationGap = 2.5;  // frame periods

// A camera's blobs at instant t, interpolated between the frames that bracket it.
struct Interpolated {
  int count = 0;
  std::array<Vec2, kIrSlots> px;
  std::array<int, kIrSlots> source;  // blob index in the earlier frame
  size_t frame = 0;                  // the earlier frame
  double s = 0;                      // fraction of the way to the later frame
};
// False when t is outside the frames, the bracketing frames are more than max_gap_us apart, or no blob
// of the earlier frame continues into the later one. `links` holds link_to_next of every frame but the last.
bool interpolate_blobs(const CameraFrames& frames, const BlobLinks& links, double max_gap_us, double t, Interpolated& out);

// A camera 0 blob that moved between two frames: what the time offset is read from.
struct MovingBlob {
  double t_us = 0;   // camera 0's frame instant
  Vec2 normalized;   // undistorted, normalized image coordinates
};
inline constexpr double kMovingPx = 1.5;  // a blob moving less per frame says little about timing

// The offset within centre_us +- search_us that makes the moving camera 0 blobs fit the rig's epipolar
// geometry best against camera 1's interpolated blobs (each against the nearest); the cost is a mean
// capped epipolar distance. Needs 30 moving blobs to be observable.
TimeOffsetEstimate search_time_offset(std::span<const MovingBlob> moving, const CameraFrames& cam1, const BlobLinks& links1,
                                      double max_gap1_us, const Camera& c0, const Camera& c1, double centre_us,
                                      double search_us);

// --- the pen ---

struct PenTrackOptions {
  TriangulationMethod method = TriangulationMethod::Optimal;
  double max_reprojection_px = 2.0;
  // Tuned on the simulated rig (perf/notes/tracking.md): the static error falls, the error at 0.5 m/s
  // grows by a few tenths of a millimetre of lag.
  OneEuroParams filter{.min_cutoff_hz = 1.0, .beta = 300.0, .derivative_cutoff_hz = 2.0};
  // The pen stays down through losses of the LED by both cameras up to max_gap_us (a hand or the object
  // hiding it from both) when it is seen again where a drawing hand could have moved it; after a gap
  // longer than short_gap_us, a pen seen elsewhere starts a new stroke.
  int64_t max_gap_us = 300000;
  int64_t short_gap_us = 60000;
  // ... and through losses by one camera up to max_bridge_us, followed on the ray of the camera that
  // still sees it (the pen's blob there moving on from its last pixel).
  int64_t max_bridge_us = 1000000;
};

struct PenSample {
  int64_t t_us = 0;         // camera 0's frame instant, rounded
  uint32_t stroke = 0;
  int64_t cam0_arrival_us = 0;  // arrival time of the camera 0 report it came from, as logged
  uint32_t cam0_line = 0;       // ... and its line in the log (0: not from a file)
  Vec3 raw = Vec3::Zero();       // triangulated, in the rig's frame (camera 0's), metres
  Vec3 filtered = Vec3::Zero();  // after the One Euro filter
  double reprojection_px = 0;
};

struct PenCounts {
  uint32_t strokes = 0;
  size_t frames_seen_by_both = 0;    // camera 0 frames with a blob in both cameras
  size_t rejected_reprojection = 0;  // of those, no blob pair within the reprojection threshold
  size_t rejected_jump = 0;          // pen down, but every fitting pair far from the last position
  size_t ambiguous = 0;              // pen up, and fitting pairs that disagree (a stray blob on the LED's epipolar line)
  size_t rejected_filter = 0;        // samples the filter refused (non-finite, or time not advancing)
  size_t bridged_frames = 0;         // pen down and seen by one camera only: followed on its ray, no sample
};

// What the triangulation system (systems/triangulate) produced over a whole log.
struct PenTrack : PenCounts {
  std::vector<PenSample> samples;
};

struct StrokeShaping {
  double simplify_tolerance = 0;  // Ramer-Douglas-Peucker, metres; 0 keeps every sample
  double resample_spacing = 0;    // arc-length resampling, metres; 0 keeps the samples' spacing
};

// down, pen..., up per stroke, with the filtered positions: a log `fire replay` can consume.
std::vector<InputEvent> pen_events(const PenTrack& track, const StrokeShaping& shaping = {});

}  // namespace fire::tracking
