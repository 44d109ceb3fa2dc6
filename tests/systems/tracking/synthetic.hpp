#pragma once
// Synthetic stereo rigs and scenes for the geometry tests: the accuracy scenario of issue 4
// (cameras 0.5 m apart converging on a 0.5 m cube 0.6 to 1.0 m away), expressed in camera 0's
// frame so a calibration's gauge (camera 0 at the origin) compares directly.
#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "engine/camera.hpp"
#include "systems/tracking/calibration.hpp"

namespace fire::tracking::test {

inline Eigen::Matrix3d look_at(const Vec3& centre, const Vec3& target) {
  // World y points down like image y, so "up" for the camera is -y.
  const Vec3 z = (target - centre).normalized();
  const Vec3 x = Vec3::UnitY().cross(z).normalized();
  const Vec3 y = z.cross(x);
  Eigen::Matrix3d R;
  R.row(0) = x;
  R.row(1) = y;
  R.row(2) = z;
  return R;
}

struct Rig {
  Camera cam0, cam1;
  Vec3 cube_centre;  // in camera 0's frame
  Eigen::Matrix3d cube_axes;  // columns: the cube's edges' directions in camera 0's frame
  double cube_size;
};

// Two cameras 0.5 m apart converging on the centre of a 0.5 m cube whose centre is 0.8 m in
// front of the baseline, re-expressed with camera 0 at the origin.
inline Rig accuracy_rig(const Intrinsics& K0, const Intrinsics& K1) {
  const Vec3 c0(0, 0, 0), c1(0.5, 0.02, 0.0), target(0.25, 0.0, 0.8);
  const Eigen::Matrix3d R0w = look_at(c0, target), R1w = look_at(c1, target);
  Rig rig;
  rig.cam0 = Camera{K0, Eigen::Matrix3d::Identity(), Vec3::Zero()};
  // x_cam1 = R1w (X_w - c1) with X_w = R0w^T x_cam0 + c0.
  rig.cam1 = Camera{K1, R1w * R0w.transpose(), R1w * (c0 - c1)};
  rig.cube_centre = R0w * (target - c0);
  rig.cube_axes = R0w;  // the world's axes seen from camera 0
  rig.cube_size = 0.5;
  return rig;
}

inline Intrinsics true_intrinsics(int which) {
  return which == 0 ? Intrinsics{1342.0, 1338.5, 508.0, 389.0, -0.045, 0.0}
                    : Intrinsics{1321.0, 1324.0, 517.5, 380.5, -0.035, 0.0};
}

inline bool in_image(const Vec2& p) {
  return p.x() >= 0 && p.x() <= kWiimoteWidth - 1 && p.y() >= 0 && p.y() <= kWiimoteHeight - 1;
}

// The device's measurement: Gaussian noise, then integer pixels.
inline Vec2 measure(const Vec2& p, double sigma_px, bool round, std::mt19937_64& rng) {
  std::normal_distribution<double> noise(0.0, sigma_px);
  Vec2 q = p;
  if (sigma_px > 0) q += Vec2(noise(rng), noise(rng));
  if (round) q = Vec2(std::round(q.x()), std::round(q.y()));
  return q;
}

inline Vec3 random_in_cube(const Rig& rig, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  return rig.cube_centre + rig.cube_size * rig.cube_axes * Vec3(u(rng), u(rng), u(rng));
}

struct WandTruth {
  Vec3 A, B;
};

// A wand waved through the cube: random centres and directions, kept when both LEDs are inside
// both images and at least 4 px apart. Blob order is shuffled per camera, as the device reports
// the two look-alike LEDs in no particular order.
inline std::vector<WandObservation> wand_observations(const Rig& rig, int frames, double wand_length,
                                                      double sigma_px, bool round,
                                                      std::mt19937_64& rng,
                                                      std::vector<WandTruth>* truth = nullptr) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::bernoulli_distribution coin(0.5);
  std::vector<WandObservation> out;
  while (static_cast<int>(out.size()) < frames) {
    const Vec3 c = random_in_cube(rig, rng);
    const Vec3 d = Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
    const Vec3 A = c + 0.5 * wand_length * d, B = c - 0.5 * wand_length * d;
    const Vec2 a0 = rig.cam0.project(A), b0 = rig.cam0.project(B);
    const Vec2 a1 = rig.cam1.project(A), b1 = rig.cam1.project(B);
    if (rig.cam0.depth(A) <= 0 || rig.cam0.depth(B) <= 0 || rig.cam1.depth(A) <= 0 ||
        rig.cam1.depth(B) <= 0)
      continue;
    if (!in_image(a0) || !in_image(b0) || !in_image(a1) || !in_image(b1)) continue;
    if ((a0 - b0).norm() < 4 || (a1 - b1).norm() < 4) continue;
    WandObservation o;
    o.t_us = static_cast<int64_t>(out.size()) * 10'000;
    o.cam0 = {measure(a0, sigma_px, round, rng), measure(b0, sigma_px, round, rng)};
    o.cam1 = {measure(a1, sigma_px, round, rng), measure(b1, sigma_px, round, rng)};
    if (coin(rng)) std::swap(o.cam0[0], o.cam0[1]);
    if (coin(rng)) std::swap(o.cam1[0], o.cam1[1]);
    out.push_back(o);
    if (truth) truth->push_back({A, B});
  }
  return out;
}

// Random points in the cube seen inside both images.
inline std::vector<Vec3> visible_points(const Rig& rig, int count, std::mt19937_64& rng) {
  std::vector<Vec3> pts;
  while (static_cast<int>(pts.size()) < count) {
    const Vec3 X = random_in_cube(rig, rng);
    if (in_image(rig.cam0.project(X)) && in_image(rig.cam1.project(X))) pts.push_back(X);
  }
  return pts;
}

inline double rotation_angle_deg(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  const double c = std::clamp(((A * B.transpose()).trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / std::numbers::pi;
}

}  // namespace fire::tracking::test
