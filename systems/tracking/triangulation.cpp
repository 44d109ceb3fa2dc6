#include "systems/tracking/triangulation.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

namespace fire::tracking {
namespace {

Eigen::Matrix3d skew(const Vec3& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

// Homogeneous linear triangulation in normalized coordinates: u p3 - p1 = 0, v p3 - p2 = 0.
Vec3 triangulate_dlt(const Camera& c0, const Camera& c1, const Vec2& n0, const Vec2& n1) {
  Eigen::Matrix<double, 3, 4> P0, P1;
  P0 << c0.R, c0.t;
  P1 << c1.R, c1.t;
  Eigen::Matrix4d A;
  A.row(0) = n0.x() * P0.row(2) - P0.row(0);
  A.row(1) = n0.y() * P0.row(2) - P0.row(1);
  A.row(2) = n1.x() * P1.row(2) - P1.row(0);
  A.row(3) = n1.y() * P1.row(2) - P1.row(1);
  for (int r = 0; r < 4; ++r) A.row(r).normalize();
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d X = svd.matrixV().col(3);
  return X.head<3>() / X(3);
}

// Thesis 4.3.5: in camera 0's frame, z1 m1 = z0 Rr m0 + tr; solve [m1, -Rr m0] (z1, z0) = tr by
// the normal equations and return z0 m0, the point on camera 0's ray.
Vec3 triangulate_thesis(const Camera& c0, const Camera& c1, const Vec2& n0, const Vec2& n1) {
  const Eigen::Matrix3d Rr = c1.R * c0.R.transpose();
  const Vec3 tr = c1.t - Rr * c0.t;
  const Vec3 m0 = n0.homogeneous();
  Eigen::Matrix<double, 3, 2> A;
  A.col(0) = n1.homogeneous();
  A.col(1) = -(Rr * m0);
  const Eigen::Vector2d z = (A.transpose() * A).ldlt().solve(A.transpose() * tr);
  const Vec3 X_cam0 = z(1) * m0;
  return c0.R.transpose() * (X_cam0 - c0.t);
}

// Lindstrom (2010), "Triangulation made easy", algorithm niter2: moves the two image points
// the least (in the image metric) onto the epipolar constraint y1^T F y0 = 0. Points in
// undistorted pixels, so the correction minimizes the pixel error the noise lives in.
void correct_lindstrom(const Eigen::Matrix3d& F, Vec2& y0, Vec2& y1) {
  const Vec3 x = y1.homogeneous();  // Lindstrom's x^T E x' = 0 with x in image 1, x' in image 0
  const Vec3 xp = y0.homogeneous();
  const Eigen::Matrix2d Et = F.topLeftCorner<2, 2>();
  Eigen::Vector2d n = (F * xp).head<2>();
  Eigen::Vector2d np = (F.transpose() * x).head<2>();
  const double a = n.dot(Et * np);
  const double b = 0.5 * (n.squaredNorm() + np.squaredNorm());
  const double c = x.dot(F * xp);
  const double d = std::sqrt(std::max(0.0, b * b - a * c));
  double lambda = c / (b + d);
  Eigen::Vector2d dx = lambda * n;
  Eigen::Vector2d dxp = lambda * np;
  n -= Et * dxp;
  np -= Et.transpose() * dx;
  lambda *= 2.0 * d / (n.squaredNorm() + np.squaredNorm());
  dx = lambda * n;
  dxp = lambda * np;
  y1 -= dx;
  y0 -= dxp;
}

Vec3 triangulate_optimal(const Camera& c0, const Camera& c1, const Vec2& n0, const Vec2& n1) {
  const Eigen::Matrix3d Rr = c1.R * c0.R.transpose();
  const Vec3 tr = c1.t - Rr * c0.t;
  const Eigen::Matrix3d K0 = camera_matrix(c0.K);
  const Eigen::Matrix3d K1 = camera_matrix(c1.K);
  const Eigen::Matrix3d F = K1.inverse().transpose() * skew(tr) * Rr * K0.inverse();
  Vec2 y0 = (K0 * n0.homogeneous()).head<2>();
  Vec2 y1 = (K1 * n1.homogeneous()).head<2>();
  const double scale = F.norm();
  if (scale > 0) correct_lindstrom(F / scale, y0, y1);
  const Vec2 m0 = (K0.inverse() * y0.homogeneous()).head<2>();
  const Vec2 m1 = (K1.inverse() * y1.homogeneous()).head<2>();
  // The corrected rays meet, so the depth along ray 0 from the 2 x 2 linear system is exact.
  return triangulate_thesis(c0, c1, m0, m1);
}

}  // namespace

Triangulation triangulate(const Camera& c0, const Camera& c1, const Vec2& px0, const Vec2& px1,
                          TriangulationMethod m, double max_reprojection_px) {
  Triangulation out;
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  out.X = Vec3::Constant(nan);
  out.reprojection_error_px = nan;
  if (!px0.allFinite() || !px1.allFinite()) return out;
  const Vec2 n0 = c0.undistort_normalized(px0);
  const Vec2 n1 = c1.undistort_normalized(px1);
  if (!n0.allFinite() || !n1.allFinite()) return out;
  switch (m) {
    case TriangulationMethod::ThesisLinear: out.X = triangulate_thesis(c0, c1, n0, n1); break;
    case TriangulationMethod::Dlt: out.X = triangulate_dlt(c0, c1, n0, n1); break;
    case TriangulationMethod::Optimal: out.X = triangulate_optimal(c0, c1, n0, n1); break;
  }
  if (!out.X.allFinite()) return out;
  out.reprojection_error_px =
      std::max((c0.project(out.X) - px0).norm(), (c1.project(out.X) - px1).norm());
  out.accepted = std::isfinite(out.reprojection_error_px) && c0.depth(out.X) > 0 &&
                 c1.depth(out.X) > 0 && out.reprojection_error_px <= max_reprojection_px;
  return out;
}

}  // namespace fire::tracking
