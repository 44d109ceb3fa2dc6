#pragma once
// The simulated person, who registers an object on marks and draws a curve network on it through the
// simulated rig (platform/simulated_rig/simulated_rig.hpp: the remotes, their report timing, the wand and
// sketch scenes, the time model and the log lines), and the truth such a log holds, read back, with the
// tracker's and the calibration's errors against it.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "engine/camera.hpp"
#include "engine/common.hpp"
#include "engine/input_log.hpp"
#include "engine/mesh.hpp"
#include "engine/polygon_mesh.hpp"
#include "platform/simulated_rig/simulated_rig.hpp"
#include "systems/tracking/calibration.hpp"
#include "systems/tracking/track.hpp"

namespace fire::simulation {

// A drawing: a person registers the object on marks and draws a curve network on it (simulate_drawing).
struct DrawingOptions {
  double height_m = 0.2;      // the object is scaled to this height (its +z axis is up)
  double speed_m_s = 0.2;     // pen speed along a stroke
  double hold_s = 0.3;        // the lit pen rests this long where a stroke starts, and 2/3 of it where it ends
  double mark_hold_s = 1.0;   // the pen rests this long on a mark; `cmd mark` is logged 0.2 s before it lifts
  double tilt_deg = 10;       // the object leans its top this far toward the cameras
  int turns = 6;              // poses the object can be turned to, evenly about its up axis
  int undo_after = 3;         // the split stroke (1-based) undone by `cmd undo` and drawn again; 0: none
  int max_strokes = 0;        // stop after this many strokes (0: the whole network)
  // The marks are measured by touch (cmd table, cmd measure N, then cmd mark N without coordinates), as on an
  // object nobody modelled, instead of touched at the coordinates of the marks file.
  bool measure_marks = false;
  std::string mesh_name = "pawn.obj";  // recorded in the log's meta
};

// The curve network to draw, in the object's frame: curve k joins vertices a and b through `points`
// (points.front() at a, points.back() at b); border curves have one face.
struct DrawingCurve {
  uint32_t a = 0, b = 0;
  std::vector<Vec3> points;
  bool border = false;
  bool sharp = false;  // along a crease of the object: the person marks it sharp (cmd sharp)
};
// A walk along network curves: each curve walked from a to b (forward) or back.
struct Leg {
  uint32_t curve;
  bool forward;
};
using Chain = std::vector<Leg>;
struct DrawingNetwork {
  std::vector<Vec3> vertices;
  std::vector<DrawingCurve> curves;
  std::vector<Chain> faces;  // each face's boundary, in loop order
};

struct DrawingStats {
  int strokes = 0;          // pen strokes drawn on the object (the redrawn one included; touches of marks not)
  int border_strokes = 0;
  int split_strokes = 0;
  int undos = 0;
  int registrations = 0;    // one each time the object is put in a pose
  int poses = 0;            // how many different poses it was drawn in
  int holes = 0;            // faces opened with cmd hole
  int sharp = 0;            // touches of cmd sharp, each marking a run of crease curves
  int pieces = 0;           // strokes that end off the network: a curve drawn in pieces, turning the object between
  int mark_touches = 0;
  size_t curves_drawn = 0;  // of the network's curves
  size_t curves_total = 0;
};

struct SimulatedDrawing {
  SimulatedSession session;
  std::vector<Vec3> marks;  // the object's marks, object frame
  DrawingStats drawing;
};

// How finely simulate_drawing's `object` follows the limit surface: 1 level keeps it within a millimetre of
// the surface on the reference meshes, well inside the clearance a lit pen tip keeps from what hides it.
inline constexpr int kOccluderLevels = 1;

// The object's own frame: `positions` scaled to `height_m` along +z, the centre of its base at the origin.
Result<std::vector<Vec3>> object_frame(std::span<const Vec3> positions, double height_m);

// A tracked stroke shorter than this is taken for a touch of the pen, or loses its middle to the pauses at its
// ends (metres: the sketch's 3 mm at each end, and 2 mm to draw).
inline constexpr double kShortestStroke = 0.005;

// Closes each border loop of `mesh` narrower than `narrowest_m` (twice its vertices' farthest distance from
// their centroid), a hole too small to draw round and to tell its vertices apart on (the rook's 3 mm hole under
// its base): the loop's vertices become one, at their centroid, so the faces around it meet there. Unused vertices are dropped and the tags renumbered with the rest. Returns how many loops it
// closed, or why it cannot (a loop through a vertex twice, or a face that would use an edge a third time).
Result<int> close_small_holes(PolygonMesh& mesh, std::vector<uint32_t>& sharp_edges, std::vector<uint8_t>& border_corners,
                              double narrowest_m);

// `object` (its surface, object frame, metres: the control mesh's limit surface, limit_mesh() at
// kOccluderLevels, which is what hides the pen from a camera) placed before the rig in one of `turns` poses at
// a time, and, where it needs them, upside down and leaning further. Six marks are picked among the network's
// vertices, spread around the object at two heights, and more where a pose sees fewer than 3. The person
// touches the marks visible in the first pose (a `cmd mark` each, then `cmd register`), draws each part's first
// border loop stroke by stroke, then splitting curves, opening holes and drawing across the far side as
// drawing_plan.hpp lays out; when no stroke left is seen whole by both cameras in the current pose, the object
// is turned to the pose that sees one and registered again on the marks visible there, and a chain no pose
// sees whole is drawn in pieces. One split stroke is undone and drawn again. The LED sits at the pen's tip, on
// the limit surface, where the network's points are.
Result<SimulatedDrawing> simulate_drawing(const RigOptions& rig, const DrawingOptions& drawing, const PolygonMeshView& object,
                                          const DrawingNetwork& network);
// The network to draw from a curve network (the object's K-unrefined one on its limit surface, systems/synth).
DrawingNetwork drawing_network(const Mesh& network);

// The rig file (systems/tracking/rig_io.hpp) of the simulated rig's true cameras (make_simulated_rig) and clock
// offset: what a perfect calibration would give, for tracking a simulated session without calibrating first.
Result<std::string> true_rig_json(const RigOptions& rig);

// What a simulated log says about itself, read back from its truth and meta lines.
struct PenTruth {
  int device = 0;
  int64_t t_us = 0;  // the report's logged arrival time (the key to match a report)
  uint32_t report_line = 0;  // the line of the report it follows in the log (reports of a burst share t_us)
  Vec3 position = Vec3::Zero();
  bool lit = false;
  double speed_m_s = 0;
  double still_s = 0;
};
struct SessionTruth {
  bool has_cameras = false;
  std::array<tracking::Camera, 2> cameras;
  std::array<bool, 2> has_nominal{};
  std::array<tracking::Intrinsics, 2> nominal{};
  bool has_wand_length = false;
  double wand_length_m = 0;
  bool has_clocks = false;
  std::array<double, 2> latency_us{};
  std::vector<PenTruth> pen;  // in log order
  size_t rejected_lines = 0;  // truth or meta lines of known names with a wrong count or non-finite numbers
};
SessionTruth read_session_truth(std::span<const InputEvent> events);

struct ErrorStats {
  size_t samples = 0;
  double rms_mm = 0;
  double max_mm = 0;
};

struct PenAccuracy {
  ErrorStats static_filtered;    // the pen resting for at least settle_s
  ErrorStats settling_filtered;  // the pen resting for less than settle_s (the filter catching up)
  ErrorStats dynamic_filtered;   // the pen moving
  ErrorStats static_raw, dynamic_raw;  // the same before the One Euro filter
  size_t unmatched = 0;  // samples whose report has no pen truth line
  size_t phantom = 0;    // samples taken while the truth says the LED was off
  // The same after registering the rig's frame to the truth as a user registers it to the object,
  // by resting the pen on known points: each hold's mean filtered position against its true
  // position (register_rigid). This removes what no wand can observe (a small rotation of the
  // whole rig about camera 0, from its principal point) and keeps every other error.
  bool registered = false;
  size_t registration_points = 0;
  double registration_rms_mm = 0;
  ErrorStats registered_static, registered_dynamic;
};

// Compares each sample with the pen's true position at its camera 0 report's exposure. The truth
// is moved into camera 0's frame with camera 0's true pose (X_cam0 = R0 X + t0): the calibrated
// rig has camera 0 at its origin, so no registration stands between the two. Fails when the
// log has no camera truth.
Result<PenAccuracy> evaluate_pen_accuracy(const tracking::PenTrack& track, const SessionTruth& truth,
                                          double settle_s);

// How far a calibrated rig is from the simulator's cameras (camera 1 relative to camera 0).
struct RigErrors {
  double baseline_error_mm = 0;   // |t| of the calibrated rig minus the true camera distance
  double rotation_error_deg = 0;  // angle of R_cal^T R_true
  double direction_error_deg = 0; // angle between the baselines
  std::array<double, 2> focal_error_px{};  // mean of fx and fy errors
  std::array<double, 2> principal_point_error_px{};
  std::array<double, 2> k1_error{};
};
Result<RigErrors> compare_rig(const tracking::CalibrationResult& rig, const SessionTruth& truth);

}  // namespace fire::simulation
