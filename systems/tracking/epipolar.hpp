#pragma once
// Two-view geometry (thesis 4.3.3): fundamental matrix by the normalized 8-point algorithm,
// essential matrix and relative pose with cheirality.
#include <Eigen/Core>
#include <span>

#include "engine/camera.hpp"
#include "engine/common.hpp"

namespace fire::tracking {

// x1^T F x0 = 0 for corresponding pixels x0 (camera 0) and x1 (camera 1). Hartley-normalized,
// rank 2 enforced, scaled to unit Frobenius norm. Fails on fewer than 8 correspondences,
// mismatched sizes, non-finite input or degenerate configurations (e.g. all points on a line).
Result<Eigen::Matrix3d> fundamental_8point(std::span<const Vec2> x0, std::span<const Vec2> x1);

// Symmetric point-to-epipolar-line distance in pixels, averaged over the pairs:
// mean of (d(x1, F x0) + d(x0, F^T x1)) / 2.
double mean_epipolar_distance(const Eigen::Matrix3d& F, std::span<const Vec2> x0,
                              std::span<const Vec2> x1);

// E = K1^T F K0 (pinhole part of the intrinsics; distortion must already be removed from the
// pixels F was estimated from). Unit Frobenius norm.
Eigen::Matrix3d essential_from_fundamental(const Eigen::Matrix3d& F, const Intrinsics& K0,
                                           const Intrinsics& K1);

struct RelativePose {
  Eigen::Matrix3d R;
  Vec3 t;  // unit norm; a point X0 in camera 0 is X1 = R * X0 + t in camera 1 (up to scale)
};

// Chooses among the four (R, t) of E the one that puts the most points in front of both cameras.
// n0, n1: normalized (undistorted) coordinates. Fails on mismatched or empty input, non-finite
// E, or when no candidate puts a majority of the points in front of both cameras.
Result<RelativePose> recover_pose(const Eigen::Matrix3d& E, std::span<const Vec2> n0,
                                  std::span<const Vec2> n1);

}  // namespace fire::tracking
