#include "systems/tracking/epipolar.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <string>

namespace fire::tracking {
namespace {

// Hartley normalization: centroid to the origin, mean distance sqrt(2).
struct Normalization {
  Eigen::Matrix3d T;
  bool degenerate;
};

Normalization hartley_normalization(std::span<const Vec2> x) {
  Vec2 centroid = Vec2::Zero();
  for (const Vec2& p : x) centroid += p;
  centroid /= static_cast<double>(x.size());
  double mean_distance = 0;
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Vec2& p : x) {
    const Vec2 d = p - centroid;
    mean_distance += d.norm();
    scatter += d * d.transpose();
  }
  mean_distance /= static_cast<double>(x.size());
  Normalization n{Eigen::Matrix3d::Identity(), false};
  // Collinear points (all on one line, or all the same point) leave the fundamental matrix
  // undetermined: its null space grows. The scatter's smaller axis shows this directly.
  const Eigen::Vector2d axes = Eigen::JacobiSVD<Eigen::Matrix2d>(scatter).singularValues();
  if (!(mean_distance > 0) || axes(1) <= 1e-12 * axes(0)) {
    n.degenerate = true;
    return n;
  }
  const double s = std::sqrt(2.0) / mean_distance;
  n.T << s, 0, -s * centroid.x(), 0, s, -s * centroid.y(), 0, 0, 1;
  return n;
}

bool all_finite(std::span<const Vec2> x) {
  for (const Vec2& p : x)
    if (!p.allFinite()) return false;
  return true;
}

Eigen::Matrix3d unit_frobenius(const Eigen::Matrix3d& M) {
  // A fixed sign (largest entry positive) makes results comparable run to run.
  Eigen::Index r, c;
  M.cwiseAbs().maxCoeff(&r, &c);
  const double sign = M(r, c) < 0 ? -1.0 : 1.0;
  return sign * M / M.norm();
}

}  // namespace

Result<Eigen::Matrix3d> fundamental_8point(std::span<const Vec2> x0, std::span<const Vec2> x1) {
  using R = Result<Eigen::Matrix3d>;
  if (x0.size() != x1.size())
    return R::failure("fundamental matrix: " + std::to_string(x0.size()) + " points in image 0 but " +
                      std::to_string(x1.size()) + " in image 1");
  if (x0.size() < 8)
    return R::failure("fundamental matrix: " + std::to_string(x0.size()) +
                      " correspondences, the 8-point algorithm needs at least 8");
  if (!all_finite(x0) || !all_finite(x1))
    return R::failure("fundamental matrix: a point coordinate is not finite");
  const Normalization n0 = hartley_normalization(x0);
  const Normalization n1 = hartley_normalization(x1);
  if (n0.degenerate || n1.degenerate)
    return R::failure(std::string("fundamental matrix: degenerate configuration, the points of image ") +
                      (n0.degenerate ? "0" : "1") + " lie on a line");

  // Accumulating A^T A keeps the solve 9 x 9 whatever the number of points; with Hartley
  // normalization its condition is good enough for the smallest eigenvectors.
  Eigen::Matrix<double, 9, 9> AtA = Eigen::Matrix<double, 9, 9>::Zero();
  for (size_t i = 0; i < x0.size(); ++i) {
    const Eigen::Vector3d a = n0.T * x0[i].homogeneous();
    const Eigen::Vector3d b = n1.T * x1[i].homogeneous();
    Eigen::Matrix<double, 9, 1> row;
    row << b(0) * a(0), b(0) * a(1), b(0) * a(2), b(1) * a(0), b(1) * a(1), b(1) * a(2), b(2) * a(0),
        b(2) * a(1), b(2) * a(2);
    AtA.noalias() += row * row.transpose();
  }
  Eigen::JacobiSVD<Eigen::Matrix<double, 9, 9>> svd(AtA, Eigen::ComputeFullV);
  const auto& s = svd.singularValues();  // squares of A's singular values
  // A second (near) null direction means the points do not determine F (e.g. a planar scene).
  // These are squared singular values, computed to about 1e-16 of the largest.
  if (s(7) <= 1e-14 * s(0))
    return R::failure("fundamental matrix: degenerate configuration, the correspondences do not "
                      "determine a unique solution");
  Eigen::Matrix<double, 9, 1> f = svd.matrixV().col(8);
  Eigen::Matrix3d Fn;
  Fn << f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7), f(8);

  Eigen::JacobiSVD<Eigen::Matrix3d> fsvd(Fn, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d sv = fsvd.singularValues();
  sv(2) = 0;  // rank 2: all epipolar lines meet in the epipole
  const Eigen::Matrix3d F_rank2 = fsvd.matrixU() * sv.asDiagonal() * fsvd.matrixV().transpose();
  const Eigen::Matrix3d F = n1.T.transpose() * F_rank2 * n0.T;
  if (!F.allFinite() || !(F.norm() > 0))
    return R::failure("fundamental matrix: degenerate configuration");
  return unit_frobenius(F);
}

double mean_epipolar_distance(const Eigen::Matrix3d& F, std::span<const Vec2> x0,
                              std::span<const Vec2> x1) {
  const size_t n = std::min(x0.size(), x1.size());
  if (n == 0) return 0;
  double sum = 0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d a = x0[i].homogeneous();
    const Eigen::Vector3d b = x1[i].homogeneous();
    const Eigen::Vector3d line1 = F * a;               // in image 1
    const Eigen::Vector3d line0 = F.transpose() * b;   // in image 0
    const double d1 = std::abs(b.dot(line1)) / line1.head<2>().norm();
    const double d0 = std::abs(a.dot(line0)) / line0.head<2>().norm();
    sum += 0.5 * (d0 + d1);
  }
  return sum / static_cast<double>(n);
}

Eigen::Matrix3d essential_from_fundamental(const Eigen::Matrix3d& F, const Intrinsics& K0,
                                           const Intrinsics& K1) {
  const Eigen::Matrix3d E = camera_matrix(K1).transpose() * F * camera_matrix(K0);
  return E / E.norm();
}

Result<RelativePose> recover_pose(const Eigen::Matrix3d& E, std::span<const Vec2> n0,
                                  std::span<const Vec2> n1) {
  using R = Result<RelativePose>;
  if (n0.size() != n1.size())
    return R::failure("pose recovery: " + std::to_string(n0.size()) + " points in image 0 but " +
                      std::to_string(n1.size()) + " in image 1");
  if (n0.empty()) return R::failure("pose recovery: no correspondences");
  if (!E.allFinite()) return R::failure("pose recovery: the essential matrix is not finite");
  if (!all_finite(n0) || !all_finite(n1))
    return R::failure("pose recovery: a point coordinate is not finite");

  Eigen::JacobiSVD<Eigen::Matrix3d> svd(E, Eigen::ComputeFullU | Eigen::ComputeFullV);
  if (!(svd.singularValues()(1) > 1e-9 * svd.singularValues()(0)))
    return R::failure("pose recovery: the essential matrix has rank below 2");
  Eigen::Matrix3d U = svd.matrixU();
  Eigen::Matrix3d V = svd.matrixV();
  if (U.determinant() < 0) U.col(2) *= -1;
  if (V.determinant() < 0) V.col(2) *= -1;
  Eigen::Matrix3d W;
  W << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  const Eigen::Matrix3d Ra = U * W * V.transpose();
  const Eigen::Matrix3d Rb = U * W.transpose() * V.transpose();
  const Vec3 u = U.col(2);
  const RelativePose candidates[4] = {{Ra, u}, {Ra, -u}, {Rb, u}, {Rb, -u}};

  int best = -1;
  size_t best_count = 0;
  for (int c = 0; c < 4; ++c) {
    size_t in_front = 0;
    for (size_t i = 0; i < n0.size(); ++i) {
      // Depths z0, z1 with z1 * m1 = R * z0 * m0 + t, in the least-squares sense.
      const Vec3 m0 = n0[i].homogeneous();
      const Vec3 m1 = n1[i].homogeneous();
      Eigen::Matrix<double, 3, 2> A;
      A.col(0) = candidates[c].R * m0;
      A.col(1) = -m1;
      const Eigen::Vector2d z = (A.transpose() * A).ldlt().solve(-A.transpose() * candidates[c].t);
      if (z(0) > 0 && z(1) > 0) ++in_front;
    }
    if (in_front > best_count) {
      best_count = in_front;
      best = c;
    }
  }
  if (best < 0 || 2 * best_count <= n0.size())
    return R::failure("pose recovery: no relative pose puts a majority of the points in front of "
                      "both cameras (" + std::to_string(best_count) + " of " +
                      std::to_string(n0.size()) + ")");
  return candidates[best];
}

}  // namespace fire::tracking
