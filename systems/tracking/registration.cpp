#include "systems/tracking/registration.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <string>

namespace fire::tracking {
namespace {

// True when the points span less than a plane: the second principal axis is negligible.
bool collinear(std::span<const Vec3> p, const Vec3& centroid) {
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Vec3& q : p) scatter += (q - centroid) * (q - centroid).transpose();
  const Eigen::Vector3d s = Eigen::JacobiSVD<Eigen::Matrix3d>(scatter).singularValues();
  return !(s(1) > 1e-12 * s(0));
}

}  // namespace

Result<RigidTransform> register_rigid(std::span<const Vec3> measured, std::span<const Vec3> model) {
  using R = Result<RigidTransform>;
  if (measured.size() != model.size())
    return R::failure("registration: " + std::to_string(measured.size()) + " measured points but " +
                      std::to_string(model.size()) + " model points");
  if (measured.size() < 3)
    return R::failure("registration: " + std::to_string(measured.size()) +
                      " point pairs, a rigid transform needs at least 3");
  for (size_t i = 0; i < measured.size(); ++i)
    if (!measured[i].allFinite() || !model[i].allFinite())
      return R::failure("registration: point pair " + std::to_string(i) + " is not finite");

  const double n = static_cast<double>(measured.size());
  Vec3 mean_measured = Vec3::Zero(), mean_model = Vec3::Zero();
  for (size_t i = 0; i < measured.size(); ++i) {
    mean_measured += measured[i];
    mean_model += model[i];
  }
  mean_measured /= n;
  mean_model /= n;
  if (collinear(measured, mean_measured) || collinear(model, mean_model))
    return R::failure("registration: the points are collinear, the rotation about their line is "
                      "undetermined");

  // Umeyama (1991) without scale: R = U S V^T from the cross-covariance, S fixing a reflection.
  Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < measured.size(); ++i)
    cross += (model[i] - mean_model) * (measured[i] - mean_measured).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cross, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d s(1, 1, 1);
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) s(2) = -1;
  RigidTransform T;
  T.R = svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
  T.t = mean_model - T.R * mean_measured;
  double sum = 0;
  for (size_t i = 0; i < measured.size(); ++i)
    sum += (T.R * measured[i] + T.t - model[i]).squaredNorm();
  T.rms_residual = std::sqrt(sum / n);
  return T;
}

}  // namespace fire::tracking
