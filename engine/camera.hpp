#pragma once
// Pinhole camera with two-term radial distortion, the model of a Wii Remote IR camera.
// Pixels follow the device: x right in 0..1023, y down in 0..767.
// Engine data, so that the simulated rig in platform/ projects with it as the tracking systems do; its
// types keep the namespace fire::tracking they had in systems/tracking/.
#include <Eigen/Core>

#include "engine/common.hpp"
#include "engine/ir_report.hpp"

namespace fire::tracking {

using Vec2 = Eigen::Vector2d;

struct Intrinsics {
  double fx, fy, cx, cy, k1 = 0, k2 = 0;
};

// 1024 x 768, about 41 x 31 degrees field of view: fx = fy = 1330, centre (512, 384), no distortion.
Intrinsics wiimote_nominal_intrinsics();

// The pinhole part [fx 0 cx; 0 fy cy; 0 0 1].
Eigen::Matrix3d camera_matrix(const Intrinsics& K);

// Normalized coordinates (x/z, y/z) -> pixels, applying the radial distortion 1 + k1 r^2 + k2 r^4.
Vec2 distort_and_scale(const Intrinsics& K, const Vec2& normalized);

struct Camera {
  Intrinsics K{};
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Vec3 t = Vec3::Zero();  // x_cam = R * X_world + t

  // World point -> pixel, with radial distortion. Points behind the camera give non-finite or
  // meaningless pixels; callers that care check depth() first.
  Vec2 project(const Vec3& X_world) const;
  // Depth of a world point along the optical axis (positive in front of the camera).
  double depth(const Vec3& X_world) const;
  // Unit direction in the WORLD frame from the centre through the (distorted) pixel.
  Vec3 ray(const Vec2& pixel) const;
  // Camera centre in world coordinates.
  Vec3 centre() const;
  // Pixel -> undistorted normalized coordinates (iterative inverse of k1, k2).
  Vec2 undistort_normalized(const Vec2& pixel) const;
};

}  // namespace fire::tracking
