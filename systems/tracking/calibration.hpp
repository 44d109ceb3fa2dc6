#pragma once
// Stereo calibration from a waved two-LED wand, as IR motion capture systems calibrate: the
// camera sees at most four blobs, so no checkerboard. Nominal intrinsics -> robust essential
// matrix -> relative pose -> metric scale from the wand length -> sparse bundle adjustment.
#include <array>
#include <cstdint>
#include <functional>
#include <span>

#include "engine/camera.hpp"
#include "engine/common.hpp"

namespace fire::tracking {

// The two wand LEDs seen by each camera at one (already time-aligned) instant. The LEDs look
// alike, so the order of the blobs in cam0 and cam1 is unknown and need not agree. A blob a
// camera did not see is NaN; frames without both LEDs in both cameras are counted as rejected.
struct WandObservation {
  int64_t t_us = 0;
  std::array<Vec2, 2> cam0;
  std::array<Vec2, 2> cam1;
};

// The bundle adjustment's state, for showing it converge. Reported at the starting point, after
// each accepted Levenberg-Marquardt step, where the adjustment resumes without the outlying frames
// (fewer frames, same iteration), and once when it has stopped (finished).
struct CalibrationProgress {
  int iteration = 0;  // Levenberg-Marquardt iterations so far, rejected steps included
  int frames = 0;     // wand frames in the adjustment
  double reprojection_rms_px = 0;  // as CalibrationResult::reprojection_rms_px, bit for bit when finished
  // The same per camera: sqrt(camera c's sum of squared residuals / (2 blobs * 2 coords * frames)).
  std::array<double, 2> camera_rms_px{};
  bool finished = false;  // the adjustment has stopped; iteration is CalibrationResult::iterations
};

struct CalibrationOptions {
  Intrinsics nominal0, nominal1;
  double wand_length_m = 0.3;
  int max_iterations = 100;  // Levenberg-Marquardt iterations of the bundle adjustment
  // Only reads: the result is the same with or without it. Unset, nothing extra is computed.
  std::function<void(const CalibrationProgress&)> on_iteration = nullptr;
};

struct CalibrationResult {
  Camera cam0, cam1;  // cam0 at the world origin (R = I, t = 0); metres
  // Root mean square of the per-coordinate residuals (x and y counted separately), pixels,
  // over the observations used: sqrt(sum of squared residuals / (4 blobs * 2 coords * frames)).
  double reprojection_rms_px = 0;
  // The same residuals as the RMS of the 2D error per blob: sqrt(2) * reprojection_rms_px.
  double reprojection_rms_2d_px = 0;
  // RMS over the used frames of |A - B| - wand length, with A, B triangulated (Optimal method)
  // from the calibrated cameras, millimetres. (Inside the adjustment the length is fixed.)
  double wand_length_error_mm = 0;
  // Camera 1's latency minus camera 0's when the wand was waved (calibrate_wand_streams; 0 from
  // calibrate_wand alone). Where tracking starts; it changes whenever a remote reconnects.
  double time_offset_us = 0;
  int observations_used = 0;
  int observations_rejected = 0;
  int iterations = 0;
};

// Fails on a non-positive or non-finite wand length, fewer than 8 usable observations, a wand
// never seen by one camera (all its blobs non-finite), or degenerate motion (e.g. the wand
// never moving or moving along a line).
Result<CalibrationResult> calibrate_wand(std::span<const WandObservation> obs,
                                         const CalibrationOptions& o);

}  // namespace fire::tracking
