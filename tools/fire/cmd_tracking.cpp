// fire simulate wand|sketch, fire calibrate, fire track: the stereo rig from device reports to pen
// strokes, and the simulated rig that proves its accuracy (systems/tracking).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "engine/input_log.hpp"
#include "platform/cage_io.hpp"
#include "platform/files.hpp"
#include "platform/obj.hpp"
#include "platform/wiimote/device.hpp"
#include "platform/wiimote/roles.hpp"
#include "systems/synth/network_from_mesh.hpp"
#include "systems/tracking/calibration.hpp"
#include "systems/tracking/rig_io.hpp"
#include "tools/simulation/simulate.hpp"
#include "systems/tracking/track.hpp"
#include "systems/triangulate/triangulate.hpp"
#include "tools/app/calibrate_live.hpp"
#include "tools/fire/commands.hpp"
#include "tools/app/session_rig.hpp"
#include "tools/app/session_store.hpp"

namespace fire::cli {
namespace {

using nlohmann::ordered_json;
using namespace fire::tracking;
using namespace fire::simulation;

int fail(const std::string& command, const std::string& message) {
  std::cerr << "fire " << command << ": " << message << "\n";
  return 1;
}

// A number, or null where there is nothing to measure (JSON has no NaN).
ordered_json number_or_null(double v, bool present = true) { return present && std::isfinite(v) ? ordered_json(v) : ordered_json(); }

ordered_json report_counts_json(const ReportCounts& c, size_t truth_lines_rejected) {
  return {{"ir", c.ir_reports},
          {"not_ir", c.not_ir},
          {"garbled", c.garbled},
          {"bad_length", c.bad_length},
          {"unknown_id", c.unknown_id},
          {"unknown_device", c.unknown_device},
          {"pad", c.pad_reports},
          {"bad_device_records", c.bad_device_records},
          {"out_of_range_blobs", c.out_of_range_slots},
          {"truth_lines_rejected", truth_lines_rejected}};
}

// --- simulate ---

struct SimulateArgs {
  RigOptions rig;
  WandOptions wand;
  SketchOptions sketch;
  DrawingOptions drawing;
  uint32_t unrefine = 2;
  std::string out_path, session_dir, rig_path, marks_path, object_path;
  std::string mesh_path;  // empty: the bundled pawn
};

void add_rig_options(CLI::App* cmd, SimulateArgs& a) {
  RigOptions& r = a.rig;
  auto* out = cmd->add_option("-o,--output", a.out_path, "input log to write (engine/INPUT_LOG.md)");
  auto* session = cmd->add_option("--session", a.session_dir,
                                  "write a session folder instead (engine/SESSION.md), which fire calibrate, fire track, "
                                  "fire replay and fire app read as they read a log");
  out->excludes(session);
  session->excludes(out);
  cmd->add_option("--rig", a.rig_path,
                  "with --session: the rig file (from fire calibrate) the session keeps as its rig.json, so that "
                  "fire replay DIR and fire app DIR triangulate its reports with no --rig")
      ->needs(session);
  cmd->add_option("--seed", r.seed, "seed of the noise, timing, motion, dropouts, stray blob and occlusions (same seeds and options, byte-identical log)")
      ->capture_default_str();
  cmd->add_option("--rig-seed", r.rig_seed,
                  "seed of the true cameras; a sketch tracks with the rig calibrated from a wand log only if both share it")
      ->capture_default_str();
  cmd->add_option("--noise-px", r.noise_px, "Gaussian blob noise per coordinate, pixels, before rounding to integers")->capture_default_str();
  cmd->add_option("--focal-error", r.focal_error,
                  "fraction by which the nominal focal lengths calibration starts from are wrong (0.02: 2 % too long)")
      ->capture_default_str();
  cmd->add_option("--focal-px", r.focal_px, "mean true focal length, pixels (each camera differs by up to 1 %)")->capture_default_str();
  cmd->add_option("--k1", r.k1, "radial distortion k1 of the true cameras (varies by 20 % per camera)")->capture_default_str();
  cmd->add_option("--k2", r.k2, "radial distortion k2 of the true cameras (calibration keeps k2 at 0)")->capture_default_str();
  cmd->add_option("--baseline", r.baseline_m, "distance between the cameras, metres")->capture_default_str();
  cmd->add_option("--distance", r.target_distance_m, "distance to the point both cameras converge on, metres")->capture_default_str();
  cmd->add_option("--rate-hz", r.rate_hz, "nominal report rate of each remote")->capture_default_str();
  cmd->add_option("--drift-ppm", r.drift_ppm, "how much faster camera 1's frame clock runs than camera 0's, ppm")->capture_default_str();
  cmd->add_option("--latency-ms", r.latency_ms, "camera 0's report latency, milliseconds")->capture_default_str();
  cmd->add_option("--clock-offset-ms", r.clock_offset_ms,
                  "camera 1's extra latency, milliseconds: its reports stamp each instant this much later")
      ->capture_default_str();
  cmd->add_option("--jitter-ms", r.jitter_ms, "standard deviation of the report arrival jitter, milliseconds")->capture_default_str();
  cmd->add_option("--dropout", r.dropout, "probability that a report is lost")->capture_default_str();
  cmd->add_option("--burst", r.burst, "probability that a report is held and arrives together with the next one (Bluetooth bursts)")
      ->capture_default_str();
  cmd->add_option("--stray", r.stray, "fraction of the time camera 1 sees a stray reflection blob")->capture_default_str();
  cmd->add_option("--occlusion", r.occlusion_per_s, "brief hand occlusions (50 to 300 ms) per second per camera")->capture_default_str();
}

ordered_json simulation_json(const char* scenario, const SimulateArgs& a, const SimulatedSession& s) {
  const SimulationStats& st = s.stats;
  ordered_json out;
  out["scenario"] = scenario;
  out["log"] = a.session_dir.empty() ? a.out_path : SessionPaths{a.session_dir}.log();
  out["seed"] = a.rig.seed;
  out["rig_seed"] = a.rig.rig_seed;
  out["duration_s"] = st.duration_s;
  out["reports"] = {st.reports[0], st.reports[1]};
  out["dropped"] = {st.dropped[0], st.dropped[1]};
  out["led_images"] = st.led_images;
  out["occluded"] = st.occluded;
  out["out_of_view"] = st.out_of_view;
  out["merged"] = st.merged;
  out["stray_frames"] = st.stray_frames;
  if (std::string(scenario) == "sketch") out["strokes"] = st.strokes;
  return out;
}

// The simulated events to -o's log, or to --session's folder with the rig's copy and the marks (when given).
Status write_log_or_session(const SimulateArgs& a, const std::vector<InputEvent>& events, const std::string& marks_json) {
  if (a.session_dir.empty()) return write_file_atomic(a.out_path, format_input_log(events));
  std::string rig_json;
  if (!a.rig_path.empty()) {
    Result<std::string> text = read_text_file(a.rig_path);
    if (!text) return Status::failure(text.error());
    InputLog log;
    log.events = events;
    if (auto rig = tracking_rig_from_json(*text, a.rig_path, log, a.session_dir); !rig) return Status::failure(rig.error());
    rig_json = std::move(*text);
  }
  return write_log_session(a.session_dir, World{}, events, rig_json, marks_json);
}

int write_simulation(const char* scenario, const SimulateArgs& a, const Result<SimulatedSession>& s) {
  const std::string command = std::string("simulate ") + scenario;
  if (!s) return fail(command, s.error());
  if (Status w = write_log_or_session(a, s->events, ""); !w) return fail(command, w.error);
  std::cout << simulation_json(scenario, a, *s).dump() << "\n";
  return 0;
}

// Checked before simulating, which takes seconds.
bool output_chosen(const char* scenario, const SimulateArgs& a) {
  if (!a.out_path.empty() || !a.session_dir.empty()) return true;
  fail(std::string("simulate ") + scenario, "give where to write it: -o LOG, or --session DIR");
  return false;
}

int run_simulate_wand(const SimulateArgs& a) {
  if (!output_chosen("wand", a)) return 1;
  return write_simulation("wand", a, simulate_wand(a.rig, a.wand));
}

// --mesh, or the bundled pawn.
Result<std::string> object_path(const SimulateArgs& a) {
  if (!a.mesh_path.empty()) return a.mesh_path;
  auto path = bundled_data_file(kDefaultMesh);
  if (!path) return Result<std::string>::failure(path.error() + "; choose the object with --mesh");
  return path;
}

int run_simulate_sketch(const SimulateArgs& a) {
  if (!output_chosen("sketch", a)) return 1;
  auto path = object_path(a);
  if (!path) return fail("simulate sketch", path.error());
  Result<PolygonMesh> mesh = read_obj(*path);
  if (!mesh) return fail("simulate sketch", mesh.error() + " (choose the object with --mesh)");
  SketchOptions sketch = a.sketch;
  sketch.mesh_name = path->substr(path->find_last_of('/') + 1);
  return write_simulation("sketch", a, simulate_sketch(a.rig, sketch, mesh->view()));
}

int run_simulate_drawing(const SimulateArgs& a) {
  const std::string command = "simulate drawing";
  if (!output_chosen("drawing", a)) return 1;
  if (!std::isfinite(a.drawing.height_m) || !(a.drawing.height_m > 0)) return fail(command, "--height must be a positive number of metres");
  auto object_file = object_path(a);
  if (!object_file) return fail(command, object_file.error());
  const std::string& mesh_path = *object_file;
  Result<std::string> mesh_text = read_text_file(mesh_path);
  if (!mesh_text) return fail(command, mesh_text.error() + " (choose the object with --mesh)");
  Result<PolygonMesh> mesh = parse_obj(*mesh_text, mesh_path);
  if (!mesh) return fail(command, mesh.error() + " (choose the object with --mesh)");
  Result<SubdivisionTags> tags = parse_obj_tags(*mesh_text, mesh_path, *mesh);
  if (!tags) return fail(command, tags.error());
  Result<std::vector<Vec3>> placed = object_frame(mesh->positions, a.drawing.height_m);
  if (!placed) return fail(command, mesh_path + ": " + placed.error());
  mesh->positions = std::move(*placed);
  Result<int> closed_holes = close_small_holes(*mesh, tags->sharp_edges, tags->border_corners, kShortestStroke);
  if (!closed_holes) return fail(command, mesh_path + ": " + closed_holes.error());
  const PolygonMeshView control = mesh->view(mesh_path);
  Result<Mesh> network = network_from_mesh(
      control, UnrefineOptions{.unrefine = a.unrefine, .limit = true, .sharp_edges = tags->sharp_edges, .border_corners = tags->border_corners});
  if (!network) return fail(command, network.error());
  DrawingOptions options = a.drawing;
  options.mesh_name = mesh_path.substr(mesh_path.find_last_of('/') + 1);
  Result<PolygonMesh> surface = limit_mesh(control, kOccluderLevels, tags->sharp_edges, tags->border_corners);
  if (!surface) return fail(command, surface.error());
  Result<SimulatedDrawing> drawing = simulate_drawing(a.rig, options, surface->view(), drawing_network(*network));
  if (!drawing) return fail(command, mesh_path + ": " + drawing.error());

  const std::string marks = marks_to_json(drawing->marks);
  // The object as a cage, its crease tags with it, so that fire eval measures against the limit surface drawn on.
  Cage placed_object;
  placed_object.mesh = *mesh;
  placed_object.sharp_edges = tags->sharp_edges;
  placed_object.border_corners = tags->border_corners;
  const Result<std::string> object =
      encode_cage_obj(placed_object, LengthUnit::Metre, options.mesh_name + " scaled to " + format_double(options.height_m) +
                                                        " m along +z, its base's centre at the origin (metres, the object's frame)");
  if (!object) return fail(command, mesh_path + ": " + object.error());
  // Nothing is written unless everything can be: the log last, so a log never comes without its marks.
  if (Status w = write_file_atomic(a.marks_path, marks); !w) return fail(command, w.error);
  if (Status w = write_file_atomic(a.object_path, *object); !w) return fail(command, w.error);
  if (Status w = write_log_or_session(a, drawing->session.events, marks); !w) return fail(command, w.error);
  ordered_json out = simulation_json("drawing", a, drawing->session);
  const DrawingStats& st = drawing->drawing;
  out["strokes"] = st.strokes;
  out["border_strokes"] = st.border_strokes;
  out["split_strokes"] = st.split_strokes;
  out["undos"] = st.undos;
  out["registrations"] = st.registrations;
  out["poses"] = st.poses;
  out["pieces"] = st.pieces;
  out["holes"] = st.holes;
  out["holes_closed"] = *closed_holes;
  out["sharp"] = st.sharp;
  out["mark_touches"] = st.mark_touches;
  out["curves_drawn"] = st.curves_drawn;
  out["curves_total"] = st.curves_total;
  out["marks"] = a.marks_path;
  out["object"] = a.object_path;
  std::cout << out.dump() << "\n";
  return 0;
}

// --- calibrate ---

// The rig file's "remotes" member (platform/wiimote/roles.hpp) from the log's device records.
ordered_json logged_remotes(const DeviceStreams& streams) {
  ordered_json out = ordered_json::array();
  for (int c = 0; c < 2; ++c)
    if (!streams.camera_address[c].empty())
      out.push_back({{"address", wiimote::normalize_address(streams.camera_address[c])}, {"role", c == 0 ? "camera0" : "camera1"}});
  if (!streams.pad_address.empty())
    out.push_back({{"address", wiimote::normalize_address(streams.pad_address)}, {"role", "pad"}});
  return out;
}

}  // namespace

namespace {

struct CalibrateArgs {
  std::string log_path, out_path;
  std::optional<double> wand_length_m;
  int max_iterations = 100;
  bool live = false;
  app::LiveWandOptions live_options;
};

// Shows the bundle adjustment converging on stderr: each pass's start, the frames it drops as
// outliers and its end; between them the iterations that change the printed figures, and past the
// 20th only those that lower the RMS by more than 1 % since the last line, so a slow pass stays short.
class AdjustmentPrinter {
 public:
  explicit AdjustmentPrinter(int max_iterations) : max_iterations_(max_iterations) {}

  void show(const CalibrationProgress& p) {
    constexpr int kEveryIteration = 20;
    char figures[160];
    std::snprintf(figures, sizeof figures, ": reprojection %.3f px (camera 0 %.3f, camera 1 %.3f)",
                  p.reprojection_rms_px, p.camera_rms_px[0], p.camera_rms_px[1]);
    if (p.iteration == 0) ++pass_;  // an end report is never iteration 0: an adjustment runs at least one
    std::string what = "bundle adjustment pass " + std::to_string(pass_);
    std::string after;
    if (p.finished) {
      what += p.iteration >= max_iterations_ ? " stopped at the iteration limit after " : " converged after ";
      what += std::to_string(p.iteration) + " iterations";
    } else {
      what += ", iteration " + std::to_string(p.iteration);
      if (p.iteration == 0) {
        after = ", " + std::to_string(p.frames) + " wand frames";
      } else if (p.frames < frames_) {
        const int dropped = frames_ - p.frames;
        after = " without " + std::to_string(dropped) + (dropped == 1 ? " outlying frame" : " outlying frames");
      } else if (figures == printed_figures_ ||
                 (p.iteration > kEveryIteration && !(p.reprojection_rms_px < 0.99 * printed_rms_))) {
        return;
      }
    }
    frames_ = p.frames;
    printed_rms_ = p.reprojection_rms_px;
    printed_figures_ = figures;
    std::cerr << "fire calibrate: " << what << figures << after << "\n";
  }

 private:
  int max_iterations_;
  int pass_ = 0;
  int frames_ = 0;
  double printed_rms_ = 0;
  std::string printed_figures_;
};

// The wand's reports: the log or folder given, or (--live) those the remotes send now, recorded.
Result<InputLog> wand_log(const CalibrateArgs& a, std::vector<std::string>& notes) {
  if (!a.live) return read_log_or_session(a.log_path, notes);
  app::LiveWandOptions live = a.live_options;
  if (a.wand_length_m) live.wand_length_m = *a.wand_length_m;
  auto events = app::record_live_wand(live);
  if (!events) return Result<InputLog>::failure(events.error());
  InputLog log;
  log.events = std::move(*events);
  return log;
}

int run_calibrate(const CalibrateArgs& a) {
  const std::string command = "calibrate";
  if (a.live != a.log_path.empty())
    return fail(command, "give the LOG (or session folder) of a waved wand, or --live, not both");
  if (a.live && a.live_options.session_dir.empty())
    return fail(command, "--live records the remotes' reports into a new session folder: give --session DIR");
  // Bounded: the fake rig simulates the whole stretch before it starts.
  if (a.live && !(a.live_options.max_s > 0 && a.live_options.max_s <= 3600))
    return fail(command, "--max-seconds must be more than 0 and at most 3600");
  std::vector<std::string> notes;
  Result<InputLog> log = wand_log(a, notes);
  if (!log) return fail(command, log.error());
  for (const std::string& note : notes) std::cerr << "fire calibrate: " << note << "\n";
  const SessionTruth truth = read_session_truth(log->events);
  CalibrationOptions options;
  options.nominal0 = truth.has_nominal[0] ? truth.nominal[0] : wiimote_nominal_intrinsics();
  options.nominal1 = truth.has_nominal[1] ? truth.nominal[1] : wiimote_nominal_intrinsics();
  options.wand_length_m = a.wand_length_m ? *a.wand_length_m : truth.has_wand_length ? truth.wand_length_m : 0.3;
  options.max_iterations = a.max_iterations;
  AdjustmentPrinter printer(a.max_iterations);
  options.on_iteration = [&printer](const CalibrationProgress& p) { printer.show(p); };
  if (!std::isfinite(options.wand_length_m) || !(options.wand_length_m > 0))
    return fail(command, "--wand-length must be a positive number of metres");
  DeviceStreams streams = decode_device_streams(log->events);
  const ReportCounts counts = streams.counts;
  const ordered_json remotes = logged_remotes(streams);
  Result<WandCalibration> cal = calibrate_wand_streams(std::move(streams), options);
  if (!cal) return fail(command, (a.live ? a.live_options.session_dir : a.log_path) + ": " + cal.error());
  std::string rig_text = rig_to_json(cal->rig);
  // The remotes the wand was seen by, so tracking can refuse a log drawn with other ones; a log that names none
  // (a simulated wand) keeps those of the rig file it replaces, which assign the cameras' roles by address.
  ordered_json kept;
  Result<std::string> old = is_directory(a.out_path) ? Result<std::string>::failure("") : read_text_file(a.out_path);
  if (remotes.empty() && old) {
    const ordered_json previous = ordered_json::parse(*old, nullptr, false);
    if (previous.is_object() && previous.contains("remotes")) {
      kept = previous["remotes"];
      std::cerr << "fire calibrate: " << a.out_path << ": kept its \"remotes\" (the wand log names none)\n";
    }
  }
  if (!remotes.empty() || !kept.is_null()) {
    ordered_json rig = ordered_json::parse(rig_text);
    rig["remotes"] = remotes.empty() ? kept : remotes;
    rig_text = rig.dump(2) + "\n";
  }
  // A rig is the work of a calibration: the one replaced is kept beside the new one, never dropped silently.
  const std::string backup = a.out_path + ".bak";
  const bool replaced = old && *old != rig_text;
  if (replaced) {
    if (Status w = write_file_atomic(backup, *old); !w) return fail(command, w.error + " (the old rig is left as it was)");
    std::cerr << "fire calibrate: " << a.out_path << ": the rig it replaces is kept as " << backup << "\n";
  }
  if (Status w = write_file_atomic(a.out_path, rig_text); !w) return fail(command, w.error);

  const CalibrationResult& r = cal->rig;
  ordered_json out;
  out["rig"] = a.out_path;
  if (replaced) out["previous_rig"] = backup;
  out["reprojection_rms_px"] = r.reprojection_rms_px;
  out["reprojection_rms_2d_px"] = r.reprojection_rms_2d_px;
  out["wand_length_error_mm"] = r.wand_length_error_mm;
  out["wand_length_m"] = options.wand_length_m;
  out["observations_used"] = r.observations_used;
  out["observations_rejected"] = r.observations_rejected;
  out["iterations"] = r.iterations;
  out["calibrations"] = cal->calibrations;
  out["time_offset_ms"] = cal->time_offset_used_us * 1e-3;
  out["time_offset_observable"] = cal->time_offset.observable;
  out["time_offset_samples"] = cal->time_offset.samples;
  out["camera0_frames"] = cal->extraction.frames;
  out["frames_without_two_blobs"] = cal->extraction.not_two_blobs;
  out["frames_without_partner"] = cal->extraction.no_partner;
  out["static_blobs_removed"] = cal->static_blobs_removed;
  out["rejected_reports"] = counts.rejected_reports();
  out["reports"] = report_counts_json(counts, truth.rejected_lines);
  if (truth.has_cameras) {  // a simulated log: how far the rig is from the true cameras
    const Result<RigErrors> e = compare_rig(r, truth);
    out["rig_baseline_error_mm"] = e->baseline_error_mm;
    out["rig_rotation_error_deg"] = e->rotation_error_deg;
    out["rig_baseline_direction_error_deg"] = e->direction_error_deg;
    out["rig_focal_error_px"] = {e->focal_error_px[0], e->focal_error_px[1]};
    out["rig_principal_point_error_px"] = {e->principal_point_error_px[0], e->principal_point_error_px[1]};
    out["rig_k1_error"] = {e->k1_error[0], e->k1_error[1]};
  }
  if (truth.has_clocks) out["true_time_offset_ms"] = (truth.latency_us[1] - truth.latency_us[0]) * 1e-3;
  std::cout << out.dump() << "\n";
  return 0;
}

// --- track ---

struct TrackArgs {
  std::string log_path, rig_path, out_path;
  bool truth = false;
  std::string method = "optimal";
  std::optional<double> time_offset_ms;
  PenTrackOptions options;
  double max_gap_ms = static_cast<double>(PenTrackOptions{}.max_gap_us) * 1e-3;
  double max_bridge_ms = static_cast<double>(PenTrackOptions{}.max_bridge_us) * 1e-3;
  double simplify_mm = 0, resample_mm = 0;
  double settle_s = 0.25;
};

int run_track(const TrackArgs& a) {
  const std::string command = "track";
  TrackArgs args = a;
  if (args.method == "thesis")
    args.options.method = TriangulationMethod::ThesisLinear;
  else if (args.method == "dlt")
    args.options.method = TriangulationMethod::Dlt;
  else if (args.method == "optimal")
    args.options.method = TriangulationMethod::Optimal;
  else
    return fail(command, "unknown --method '" + args.method + "' (thesis, dlt or optimal)");
  const OneEuroParams& f = args.options.filter;
  for (auto [value, name] : {std::pair{args.options.max_reprojection_px, "--max-reprojection-px"}, {f.min_cutoff_hz, "--min-cutoff"},
                             {f.derivative_cutoff_hz, "--dcutoff"}})
    if (!std::isfinite(value) || !(value > 0)) return fail(command, std::string(name) + " must be a positive number");
  for (auto [value, name] : {std::pair{f.beta, "--beta"}, {args.max_gap_ms, "--max-gap-ms"}, {args.max_bridge_ms, "--max-bridge-ms"},
                             {args.simplify_mm, "--simplify-mm"},
                             {args.resample_mm, "--resample-mm"}, {args.settle_s, "--settle-s"}})
    if (!std::isfinite(value) || value < 0) return fail(command, std::string(name) + " must be a non-negative number");
  if (args.time_offset_ms && !(std::abs(*args.time_offset_ms) < 1e6))
    return fail(command, "--time-offset-ms must be a finite number of milliseconds");
  args.options.max_gap_us = std::llround(args.max_gap_ms * 1e3);
  args.options.max_bridge_us = std::llround(args.max_bridge_ms * 1e3);

  std::vector<std::string> notes;
  Result<InputLog> log = read_log_or_session(args.log_path, notes);
  if (!log) return fail(command, log.error());
  for (const std::string& note : notes) std::cerr << "fire track: " << note << "\n";
  const SessionTruth truth = read_session_truth(log->events);
  if (args.truth && !truth.has_cameras)
    return fail(command, args.log_path + ": --truth needs the simulator's truth lines (truth camera 0 and 1), and the log has none");
  Result<TrackingRig> loaded = load_tracking_rig(args.rig_path, *log, args.log_path);
  if (!loaded) return fail(command, loaded.error());
  const DeviceStreams streams = decode_device_streams(log->events);
  TrackingRig live = *loaded;
  if (args.time_offset_ms) live.time_offset_us = *args.time_offset_ms * 1e3;
  live.estimate_time_offset = !args.time_offset_ms;
  live.options = args.options;
  PenTrack track;
  TriangulateState state;
  track_log(log->events, live, track, &state);
  std::vector<InputEvent> events =
      pen_events(track, StrokeShaping{.simplify_tolerance = args.simplify_mm * 1e-3, .resample_spacing = args.resample_mm * 1e-3});
  InputEvent source;
  source.kind = EventKind::Meta;
  source.t_us = events.empty() ? 0 : events.front().t_us;
  source.name = "source";
  source.text = "fire track " + args.log_path + " --rig " + args.rig_path + " --method " + args.method;
  events.insert(events.begin(), source);
  if (Status w = write_file_atomic(args.out_path, format_input_log(events)); !w) return fail(command, w.error);

  ordered_json out;
  out["pen_log"] = args.out_path;
  out["method"] = args.method;
  out["samples"] = track.samples.size();
  out["strokes"] = track.strokes;
  out["time_offset_ms"] = state.time_offset_us * 1e-3;
  out["time_offset_estimated"] = !args.time_offset_ms.has_value();
  out["time_offset_estimates"] = state.offset_estimates;
  out["time_offset_observable"] = state.last_estimate.observable;
  out["time_offset_samples"] = state.last_estimate.samples;
  out["out_of_order_reports"] = state.out_of_order;
  double reprojection = 0;
  for (const PenSample& p : track.samples) reprojection += p.reprojection_px;
  out["mean_reprojection_px"] = number_or_null(reprojection / static_cast<double>(track.samples.size()), !track.samples.empty());
  out["frames_seen_by_both"] = track.frames_seen_by_both;
  out["rejected_reprojection"] = track.rejected_reprojection;
  out["rejected_jump"] = track.rejected_jump;
  out["ambiguous"] = track.ambiguous;
  out["rejected_filter"] = track.rejected_filter;
  out["bridged_frames"] = track.bridged_frames;
  out["rejected_reports"] = streams.counts.rejected_reports();
  out["reports"] = report_counts_json(streams.counts, truth.rejected_lines);
  if (args.truth) {
    const Result<PenAccuracy> acc = evaluate_pen_accuracy(track, truth, args.settle_s);
    if (!acc) return fail(command, args.log_path + ": " + acc.error());
    auto put = [&](const std::string& name, const ErrorStats& e) {
      out[name + "_rms_mm"] = number_or_null(e.rms_mm, e.samples > 0);
      out[name + "_max_mm"] = number_or_null(e.max_mm, e.samples > 0);
      out[name + "_samples"] = e.samples;
    };
    put("static", acc->static_filtered);
    put("dynamic", acc->dynamic_filtered);
    put("settling", acc->settling_filtered);
    put("raw_static", acc->static_raw);
    put("raw_dynamic", acc->dynamic_raw);
    out["registration_points"] = acc->registration_points;
    out["registration_residual_mm"] = number_or_null(acc->registration_rms_mm, acc->registered);
    put("registered_static", acc->registered_static);
    put("registered_dynamic", acc->registered_dynamic);
    out["unmatched_samples"] = acc->unmatched;
    out["phantom_samples"] = acc->phantom;
    if (truth.has_clocks) out["true_time_offset_ms"] = (truth.latency_us[1] - truth.latency_us[0]) * 1e-3;
  }
  std::cout << out.dump() << "\n";
  return 0;
}

}  // namespace

void add_tracking_commands(CLI::App& app, Registry& registry) {
  // simulate wand | sketch
  CLI::App* simulate = app.add_subcommand("simulate", "Write a simulated stereo Wii Remote session as an input log");
  simulate->require_subcommand(1);
  simulate->footer(
      "Two virtual Wii Remotes 0.5 m apart converge on a working volume 0.6 to 1.0 m away; blobs get Gaussian "
      "noise and integer pixels; each remote runs on its own drifting clock with its own latency. The log holds the "
      "exact mode 0x33 report bytes and the ground truth (truth lines) and rig facts (meta lines).");
  auto wand = std::make_shared<SimulateArgs>();
  CLI::App* w = simulate->add_subcommand("wand", "A two-LED wand waved through the working volume, for fire calibrate");
  add_rig_options(w, *wand);
  w->add_option("--duration-s", wand->wand.duration_s, "seconds of waving")->capture_default_str();
  w->add_option("--wand-length", wand->wand.length_m, "distance between the wand's LEDs, metres")->capture_default_str();
  w->footer("Prints one JSON line: reports written and dropped per camera, LED images, occluded, out of view, merged, stray frames.");
  w->callback([wand, &registry] { registry.exit_code = run_simulate_wand(*wand); });

  auto sketch = std::make_shared<SimulateArgs>();
  CLI::App* s = simulate->add_subcommand(
      "sketch", "A pen tracing curves on an object (pawn.obj scaled to 20 cm), with static holds, for fire track --truth");
  add_rig_options(s, *sketch);
  s->add_option("--duration-s", sketch->sketch.duration_s, "longest session, seconds (fewer strokes if it runs out)")->capture_default_str();
  s->add_option("--strokes", sketch->sketch.strokes, "strokes to draw")->capture_default_str();
  s->add_option("--speed", sketch->sketch.speed_m_s, "pen speed along a stroke, m/s")->capture_default_str();
  s->add_option("--hold-s", sketch->sketch.hold_s, "seconds the lit pen rests at both ends of every stroke")->capture_default_str();
  s->add_option("--height", sketch->sketch.height_m, "the object is scaled to this height, metres (its +z is up)")->capture_default_str();
  s->add_option("--mesh", sketch->mesh_path, "the object, OBJ (default: the bundled pawn, tests/data/meshes/pawn.obj)");
  s->footer("Prints one JSON line: reports written and dropped per camera, LED images, occluded, out of view, merged, stray frames, strokes.");
  s->callback([sketch, &registry] { registry.exit_code = run_simulate_sketch(*sketch); });

  auto drawing = std::make_shared<SimulateArgs>();
  CLI::App* dr = simulate->add_subcommand(
      "drawing", "A person registering an object on marks and drawing its curve network (pawn.obj at 20 cm), for fire replay --rig");
  add_rig_options(dr, *drawing);
  dr->add_option("--marks-out", drawing->marks_path, "marks file to write: the marks' ids and positions in the object's frame (JSON, metres)")
      ->required();
  dr->add_option("--object-out", drawing->object_path,
                 "the control mesh as drawn on, OBJ in metres in the object's frame (scaled, not posed): fire eval's --reference")
      ->required();
  dr->add_option("--mesh", drawing->mesh_path, "the object, OBJ with +z up (default: the bundled pawn, tests/data/meshes/pawn.obj)");
  dr->add_option("--height", drawing->drawing.height_m, "the object is scaled to this height, metres")->capture_default_str();
  dr->add_option("--unrefine", drawing->unrefine, "K: the network drawn keeps every K-th edge loop of the control mesh (fire network-from-mesh)")
      ->check(CLI::Range(1u, 64u))
      ->capture_default_str();
  dr->add_option("--speed", drawing->drawing.speed_m_s, "pen speed along a stroke, m/s")->capture_default_str();
  dr->add_option("--hold-s", drawing->drawing.hold_s, "seconds the lit pen rests where a stroke starts (two thirds of it where it ends)")
      ->capture_default_str();
  dr->add_option("--mark-hold-s", drawing->drawing.mark_hold_s, "seconds the pen rests on each mark; cmd mark is logged 0.2 s before it lifts")
      ->capture_default_str();
  dr->add_option("--tilt", drawing->drawing.tilt_deg, "degrees the object leans its top toward the cameras")->capture_default_str();
  dr->add_option("--turns", drawing->drawing.turns, "poses the object may be turned to, evenly about its up axis (twice as many where these show too little of it)")->capture_default_str();
  dr->add_option("--undo-after", drawing->drawing.undo_after, "the split stroke (1-based) undone with cmd undo and drawn again (0: none)")
      ->capture_default_str();
  dr->add_flag("--measure-marks", drawing->drawing.measure_marks,
              "the person measures the marks by touch, as on an object nobody modelled: in the first pose three touches "
              "on the table around the object (cmd table) and each mark seen (cmd measure N), then cmd register, which "
              "makes the object's frame from them; after each later registration, on the measured marks it sees (cmd "
              "mark N, no coordinates), the marks it sees for the first time are measured. --marks-out still writes the "
              "true marks, for fire eval --align with fire replay --measured-marks-out");
  dr->add_option("--max-strokes", drawing->drawing.max_strokes, "stop after this many strokes, the border always whole (0: the whole network)")
      ->capture_default_str();
  dr->footer(
      "The object stands before the rig, its middle where the cameras converge (--distance), and is turned, leaned "
      "further, set upside down and turned in finer steps (twice --turns) only as far as it needs to be (a closed "
      "object always goes upside down). Six marks are network vertices around it at a fifth and half its height (a "
      "third and two thirds on a closed object), and more on its curves where a pose sees fewer than 3, or only marks "
      "on one line. The person touches the marks both cameras see (the pen resting on each, cmd mark N X Y Z logged), "
      "logs cmd register, and draws each part's first border loop (the lowest border, "
      "or on a closed object a loop round its top faces or a handle), then splitting curves: chains of the network's "
      "curves between points already drawn, shortest first, each inside one face (an ear decomposition). The other "
      "border loops and a handle's ends are drawn round and opened with cmd hole; a handle and a closed object's "
      "top are drawn last, across the hole, from loop to loop. The curves along a crease of the object (OpenSubdiv's "
      "t crease tags in --mesh) are marked sharp as soon as they have faces on both sides, the pen touching each run "
      "of them the sketch holds as one curve (cmd sharp X Y Z). When no stroke "
      "left is seen whole by both cameras, the object is turned to a pose that shows one and registered again on the "
      "marks seen there; a chain no pose shows whole is drawn in pieces, turning the object between them. The pen's "
      "LED is at its tip, on the limit surface, which is what hides it from a camera. A border loop under 5 mm across "
      "(the rook's 3 mm hole under its base) is a hole no stroke can draw round: the object is drawn on, and written "
      "by --object-out, with it closed, its vertices one at their centre. "
      "The stray reflection (--stray) as in every session. Hand occlusions (--occlusion) are off by default: while one "
      "camera follows the pen the tracker emits no samples, so a hand passing a corner of a stroke that runs along "
      "several curves makes a chord there, a later curve meant to end at that corner misses it and is rejected, and "
      "the curves that depend on it after it. "
      "Prints one JSON line: the session's report counts, strokes (border and split), undos, registrations, poses, "
      "pieces, holes (opened with cmd hole; holes_closed: under 5 mm across, closed), sharp (touches of cmd sharp), mark touches, curves drawn of the network's total. When it cannot draw every curve (--max-strokes aside), it writes nothing and "
      "exits 1, naming the first curve it could not draw and why.");
  dr->callback([drawing, &registry] { registry.exit_code = run_simulate_drawing(*drawing); });

  // calibrate
  auto cal = std::make_shared<CalibrateArgs>();
  CLI::App* c = app.add_subcommand("calibrate", "Calibrate the stereo rig from a logged wand session, or live from the remotes (--live)");
  c->add_option("LOG", cal->log_path, "input log (or session folder) with the remotes' reports of a waved two-LED wand");
  c->add_flag("--live", cal->live,
              "record the wand from the two camera remotes now (roles by address order), into --session DIR, with each "
              "camera's progress on stderr; stops when both have seen enough of it (--coverage, --samples), on Enter, or "
              "after --max-seconds; then calibrates from the recorded reports as fire calibrate DIR would");
  c->add_option("--session", cal->live_options.session_dir, "--live: the new session folder to record into");
  c->add_option("--max-seconds", cal->live_options.max_s, "--live: stop after this long")->capture_default_str();
  c->add_option("--coverage", cal->live_options.coverage,
                "--live: share of each camera's image (an 8 x 6 grid) the wand's LEDs must have crossed")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  c->add_option("--samples", cal->live_options.samples, "--live: reports showing both LEDs each camera must have")
      ->capture_default_str();
  c->add_option("--fake-rig", cal->live_options.fake_rig_seed,
                "--live test and simulation hook, not for calibrating anything real: no hardware; two fake remotes stream "
                "the simulated wand of fire simulate wand with this seed (rig and motion), faster than real time");
  c->add_option("-o,--output", cal->out_path, "rig file to write (systems/tracking/README.md); a different rig already there is kept as FILE.bak")->required();
  c->add_option("--wand-length", cal->wand_length_m,
                "distance between the wand's LEDs, metres (default: the log's meta wand_length_m, else 0.3)");
  c->add_option("--max-iterations", cal->max_iterations, "Levenberg-Marquardt iterations per calibration")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  c->footer(
      "Starts from the log's meta nominal_intrinsics (else the Wii Remote's 1330 px, centre 512 x 384); estimates "
      "the cameras' time offset from the rig and calibrates again until it settles, showing each pass's bundle "
      "adjustment converge on stderr (reprojection RMS per coordinate, overall and per camera, at the iterations "
      "that change it; past the 20th only drops of over 1 %). Prints one JSON line: "
      "reprojection_rms_px (per coordinate), reprojection_rms_2d_px (per blob), wand_length_error_mm, observations "
      "used and rejected, time_offset_ms, rejected report counts; for simulated logs also rig_* errors against the "
      "true cameras and true_time_offset_ms.");
  c->callback([cal, &registry] { registry.exit_code = run_calibrate(*cal); });

  // track
  auto tr = std::make_shared<TrackArgs>();
  CLI::App* t = app.add_subcommand("track", "Track the pen in a logged session: pen samples and down/up events");
  t->add_option("LOG", tr->log_path, "input log (or session folder) with the remotes' reports")->required();
  t->add_option("--rig", tr->rig_path, "rig file from fire calibrate")->required();
  t->add_option("-o,--output", tr->out_path, "pen log to write: down, pen x y z (metres, camera 0's frame), up")->required();
  t->add_flag("--truth", tr->truth, "compare with the simulator's ground truth: static_rms_mm, dynamic_rms_mm");
  t->add_option("--method", tr->method, "triangulation: thesis, dlt or optimal")->capture_default_str();
  t->add_option("--max-reprojection-px", tr->options.max_reprojection_px, "reject a pen sample beyond this reprojection error")
      ->capture_default_str();
  t->add_option("--time-offset-ms", tr->time_offset_ms, "camera 1's latency minus camera 0's, held fixed (default: the rig's, then estimated from the pen's motion every 2 s)");
  t->add_option("--min-cutoff", tr->options.filter.min_cutoff_hz, "One Euro filter: cutoff at rest, Hz")->capture_default_str();
  t->add_option("--beta", tr->options.filter.beta, "One Euro filter: cutoff increase per m/s")->capture_default_str();
  t->add_option("--dcutoff", tr->options.filter.derivative_cutoff_hz, "One Euro filter: cutoff of the speed estimate, Hz")
      ->capture_default_str();
  t->add_option("--max-gap-ms", tr->max_gap_ms, "the pen stays down through shorter losses of the LED by both cameras")
      ->capture_default_str();
  t->add_option("--max-bridge-ms", tr->max_bridge_ms,
                "the pen stays down through shorter losses by one camera, followed on the other camera's ray")
      ->capture_default_str();
  t->add_option("--simplify-mm", tr->simplify_mm, "Ramer-Douglas-Peucker tolerance for the written strokes (0: off)")->capture_default_str();
  t->add_option("--resample-mm", tr->resample_mm, "arc-length spacing of the written strokes, after simplifying (0: off)")
      ->capture_default_str();
  t->add_option("--settle-s", tr->settle_s, "--truth: a resting pen counts as static after this many seconds")->capture_default_str();
  t->footer(
      "The reports go through the triangulation system frame by frame (systems/triangulate), as in a live session "
      "and in fire replay --rig: no report is used before it arrived. "
      "Prints one JSON line: samples, strokes, time_offset_ms (the last in use), rejected counts; with --truth static_rms_mm and "
      "dynamic_rms_mm (filtered samples against the truth moved into camera 0's frame by camera 0's true pose), "
      "the same before the filter (raw_*), while the pen settles (settling_*), and registered_* after registering "
      "the hold points to the truth (register_rigid), as a user registers the object.");
  t->callback([tr, &registry] { registry.exit_code = run_track(*tr); });
}

}  // namespace fire::cli
