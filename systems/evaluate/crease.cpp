#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "systems/evaluate/evaluate.hpp"

namespace fire::evaluate {

std::optional<double> bend_across_deg(const TriangleBvh& surface, const Vec3& p, const Vec3& t, double radius) {
  if (!(radius > 0) || !(t.norm() > 0)) return std::nullopt;
  const Vec3 axis = t.normalized();
  const Vec3 u = axis.unitOrthogonal(), v = axis.cross(u);
  // The cut's two branches, each read as the chord between its points about `radius` and twice that from p, so
  // that p a little off the crease (a tracked curve beside the reference's) reads each side's own slope: probes
  // all round p at both distances, each taken to its closest point of the surface, kept where both lie in the
  // cutting plane, at those distances, on one branch.
  constexpr int kProbes = 72;
  auto in_plane = [&](const Vec3& at) { return Vec3(at - p - (at - p).dot(axis) * axis); };
  auto in_cut = [&](const Vec3& at) { return std::abs((at - p).dot(axis)) <= 0.25 * radius; };
  std::vector<Vec3> branch;
  for (int k = 0; k < kProbes; ++k) {
    const double angle = 2 * std::numbers::pi * k / kProbes;
    const Vec3 out = std::cos(angle) * u + std::sin(angle) * v;
    const Vec3 near = surface.closest(p + radius * out).point, far = surface.closest(p + 2 * radius * out).point;
    const Vec3 a = in_plane(near), b = in_plane(far);
    if (!in_cut(near) || !in_cut(far) || a.norm() < 0.5 * radius || a.norm() > 1.5 * radius || b.norm() < 1.5 * radius ||
        b.norm() > 2.5 * radius || a.normalized().dot(b.normalized()) < std::cos(std::numbers::pi / 9))
      continue;
    branch.push_back((b - a).normalized());
  }
  // The two branches are the two directions farthest apart.
  double widest = -1;
  for (size_t i = 0; i < branch.size(); ++i)
    for (size_t j = i + 1; j < branch.size(); ++j) widest = std::max(widest, std::acos(std::clamp(branch[i].dot(branch[j]), -1.0, 1.0)));
  // One branch only: the ring met the surface on one side of p.
  constexpr double kTwoBranches = std::numbers::pi / 6;
  if (widest < kTwoBranches) return std::nullopt;
  return 180.0 - widest * 180.0 / std::numbers::pi;
}

}  // namespace fire::evaluate
