#pragma once
// The simulated rig: two virtual Wii Remotes watching a waved calibration wand or a pen that
// traces curves on an object, written as the engine's input log (engine/INPUT_LOG.md) with the
// exact bytes of each device report (mode 0x33) and the ground truth alongside. A device like the
// real remotes (platform/wiimote/), on the engine alone: the simulated person who draws through it,
// the truth read back and the errors against it are tools/simulation/simulate.hpp.
//
// Time model. Each remote exposes a frame every 1 / (rate * (1 + drift)) seconds of true time
// on its own crystal, starting at a random phase, so the two cameras' instants slide past each
// other. A report reaches the host `latency + jitter` later and is logged with that host
// arrival time: the log holds no exposure instants. Camera 1's latency exceeds camera 0's by
// the clock offset, which only the geometry can reveal. Every instant is data; seeded
// std::mt19937_64 streams make a session byte-identical for a given seed and options.
//
// World frame: x right, y down, z forward from the midpoint between the cameras. Log lines:
//   meta scenario wand|sketch, meta seed N rig_seed=M, meta rig OPTIONS..., meta nominal_intrinsics D fx fy cx cy k1 k2,
//   meta wand_length_m L (wand); meta mesh NAME height_m=H, meta sketch strokes=N speed_m_s=V hold_s=S (sketch)
//   truth camera D fx fy cx cy k1 k2 R00 R01 R02 R10 R11 R12 R20 R21 R22 t0 t1 t2   (x_cam = R X + t)
//   truth clock D rate_hz phase_us latency_us jitter_us
//   after every report of device D (same t_us):
//     truth wand D exposure_us ax ay az bx by bz                 (the two LEDs, world metres)
//     truth pen D exposure_us x y z led speed_m_s still_s        (led 1 = lit; still_s = time since
//                                                                 the pen stopped, 0 while moving)
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/camera.hpp"
#include "engine/common.hpp"
#include "engine/input_log.hpp"
#include "engine/polygon_mesh.hpp"

namespace fire::simulation {

struct RigOptions {
  uint64_t seed = 1;               // noise, timing, motion, dropouts, stray, occlusions
  uint64_t rig_seed = 1;           // the true cameras: calibrate and track sessions of one rig share it
  double baseline_m = 0.5;         // distance between the two cameras
  double target_distance_m = 0.8;  // both cameras converge on (0, 0, target_distance)
  double focal_px = 1330;          // mean true focal length; each camera differs by up to 1 %
  double focal_error = 0;          // the nominal (starting) focal lengths are true * (1 + focal_error)
  double k1 = 0.03, k2 = 0;        // radial distortion of the true cameras (k1 varies by 20 % per camera)
  double noise_px = 0.3;           // Gaussian blob noise per coordinate, before rounding to integers
  double rate_hz = 100;            // nominal report rate
  double drift_ppm = 100;          // camera 1's crystal runs this much faster than camera 0's
  double latency_ms = 6;           // camera 0's report latency
  double clock_offset_ms = 2;      // camera 1's extra latency
  double jitter_ms = 0.3;          // standard deviation of the arrival jitter
  double burst = 0;                // probability that a report is held and arrives with the next one
  double dropout = 0.005;          // probability that a report is lost
  double stray = 0.25;             // fraction of the time camera 1 sees a stray reflection
  double occlusion_per_s = 0;      // rate of brief hand occlusions (50 to 300 ms) per camera
};

struct WandOptions {
  double duration_s = 60;
  double length_m = 0.3;
};

struct SketchOptions {
  double duration_s = 60;  // the session stops after this even if strokes remain
  int strokes = 12;
  double speed_m_s = 0.5;
  double hold_s = 1.0;    // the pen rests this long, lit, at both ends of every stroke
  double height_m = 0.2;  // the object is scaled to this height (its +z axis is up)
  std::string mesh_name = "pawn.obj";  // recorded in the log's meta
};

struct SimulationStats {
  std::array<size_t, 2> reports{};  // written per device
  std::array<size_t, 2> dropped{};  // lost per device
  size_t led_images = 0;            // lit LEDs in front of a camera, summed over its frames
  size_t occluded = 0;              // of those, hidden by the object or a hand
  size_t out_of_view = 0;           // of those, imaged outside the 1024 x 768 image
  size_t merged = 0;                // blob pairs merged because they fell within one sensor pixel
  size_t stray_frames = 0;          // frames showing the stray reflection
  int strokes = 0;                  // sketch: strokes drawn
  double duration_s = 0;
};

struct SimulatedSession {
  std::vector<InputEvent> events;  // in log order (format_input_log writes them)
  SimulationStats stats;
};

// The accuracy rig: the true cameras and the intrinsics calibration is told to start from.
struct SimulatedRig {
  std::array<tracking::Camera, 2> cameras;
  std::array<tracking::Intrinsics, 2> nominal;
};
Result<SimulatedRig> make_simulated_rig(const RigOptions& rig);

Result<SimulatedSession> simulate_wand(const RigOptions& rig, const WandOptions& wand);
Result<SimulatedSession> simulate_sketch(const RigOptions& rig, const SketchOptions& sketch, const PolygonMeshView& mesh);

}  // namespace fire::simulation
