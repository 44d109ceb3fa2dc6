#pragma once
// A 3D point from its two images (thesis 4.3.5 and its successors).
#include "engine/camera.hpp"

namespace fire::tracking {

enum class TriangulationMethod {
  ThesisLinear,  // thesis 4.3.5: depths along both rays by linear least squares, point on ray 0
  Dlt,           // homogeneous linear system A X = 0 solved by SVD
  Optimal,       // Lindstrom 2010 (niter2) correction onto the epipolar constraint, then linear
};

struct Triangulation {
  Vec3 X = Vec3::Zero();
  double reprojection_error_px = 0;  // the larger of the two cameras' errors
  bool accepted = false;             // finite, in front of both cameras, error within the threshold
};

// px0, px1: raw (distorted) pixels; distortion is removed internally. Non-finite input gives
// accepted = false, never a crash.
Triangulation triangulate(const Camera& c0, const Camera& c1, const Vec2& px0, const Vec2& px1,
                          TriangulationMethod m, double max_reprojection_px = 2.0);

}  // namespace fire::tracking
