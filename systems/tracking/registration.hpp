#pragma once
// Rigid registration of measured points (pen tip touched on known points of the object) to the
// object's model points.
#include <Eigen/Core>
#include <span>

#include "engine/common.hpp"

namespace fire::tracking {

struct RigidTransform {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Vec3 t = Vec3::Zero();  // model = R * measured + t
  double rms_residual = 0;  // RMS of |R * measured + t - model|, same units as the points
};

// Umeyama (1991) without scale. Fails on fewer than 3 points, mismatched sizes, non-finite
// points or (nearly) collinear points.
Result<RigidTransform> register_rigid(std::span<const Vec3> measured, std::span<const Vec3> model);

}  // namespace fire::tracking
