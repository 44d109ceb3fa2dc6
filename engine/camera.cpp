#include "engine/camera.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace fire::tracking {

Intrinsics wiimote_nominal_intrinsics() {
  return Intrinsics{.fx = 1330.0, .fy = 1330.0, .cx = 512.0, .cy = 384.0, .k1 = 0.0, .k2 = 0.0};
}

Eigen::Matrix3d camera_matrix(const Intrinsics& K) {
  Eigen::Matrix3d M;
  M << K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1;
  return M;
}

Vec2 distort_and_scale(const Intrinsics& K, const Vec2& normalized) {
  const double r2 = normalized.squaredNorm();
  const double radial = 1.0 + r2 * (K.k1 + r2 * K.k2);
  return {K.fx * radial * normalized.x() + K.cx, K.fy * radial * normalized.y() + K.cy};
}

Vec2 Camera::project(const Vec3& X_world) const {
  const Vec3 x = R * X_world + t;
  return distort_and_scale(K, Vec2(x.x() / x.z(), x.y() / x.z()));
}

double Camera::depth(const Vec3& X_world) const { return R.row(2).dot(X_world) + t.z(); }

Vec3 Camera::centre() const { return -R.transpose() * t; }

Vec2 Camera::undistort_normalized(const Vec2& pixel) const {
  const Vec2 distorted((pixel.x() - K.cx) / K.fx, (pixel.y() - K.cy) / K.fy);
  if (K.k1 == 0.0 && K.k2 == 0.0) return distorted;
  // Newton on the radius: the distortion is radial, so only |n| needs solving.
  // rd = r (1 + k1 r^2 + k2 r^4); the Wii Remote's small k make this converge in a few steps.
  const double rd = distorted.norm();
  if (!(rd > 0.0)) return distorted;  // zero (centre) or NaN: nothing to undo
  double r = rd;
  for (int i = 0; i < 20; ++i) {
    const double r2 = r * r;
    const double f = r * (1.0 + r2 * (K.k1 + r2 * K.k2)) - rd;
    const double df = 1.0 + r2 * (3.0 * K.k1 + 5.0 * K.k2 * r2);
    if (!(std::abs(df) > 1e-12)) break;
    const double step = f / df;
    r -= step;
    if (std::abs(step) < 1e-15 * (1.0 + r)) break;
  }
  return distorted * (r / rd);
}

Vec3 Camera::ray(const Vec2& pixel) const {
  const Vec2 n = undistort_normalized(pixel);
  return (R.transpose() * Vec3(n.x(), n.y(), 1.0)).normalized();
}

}  // namespace fire::tracking
