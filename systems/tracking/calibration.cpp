#include "systems/tracking/calibration.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "systems/tracking/epipolar.hpp"
#include "systems/tracking/triangulation.hpp"

namespace fire::tracking {
namespace {

// Parameters shared by all frames: per camera fx, fy, cx, cy, k1; then camera 1's rotation
// increment (3) and translation (3). Camera 0 stays at the origin, which fixes the gauge;
// the fixed wand length fixes the scale. k2 stays at its nominal value: over a 41 degree
// field of view it is not separable from k1 with wand data.
constexpr int kIntrinsicParams = 5;
constexpr int kCameraParams = 2 * kIntrinsicParams + 6;
// Per frame: wand centre (3) and a 2D increment of its unit direction.
constexpr int kWandParams = 5;
using CameraVector = Eigen::Matrix<double, kCameraParams, 1>;
using CameraBlock = Eigen::Matrix<double, kCameraParams, kCameraParams>;
using WandVector = Eigen::Matrix<double, kWandParams, 1>;
using WandBlock = Eigen::Matrix<double, kWandParams, kWandParams>;
using CrossBlock = Eigen::Matrix<double, kCameraParams, kWandParams>;

// A usable frame with its blobs ordered so that cam0[k] and cam1[k] are the same LED.
struct Frame {
  std::array<Vec2, 2> cam0, cam1;
};

struct Wand {
  Vec3 centre;
  Vec3 direction;  // unit, from LED B to LED A
};

struct Model {
  Intrinsics K[2];
  Eigen::Matrix3d R1;
  Vec3 t1;
  std::vector<Wand> wands;
};

bool finite_pair(const std::array<Vec2, 2>& p) { return p[0].allFinite() && p[1].allFinite(); }

Eigen::Matrix3d rotation_from_vector(const Vec3& w) {
  const double angle = w.norm();
  if (angle < 1e-300) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

// Two unit vectors orthogonal to d, a basis for the direction's increment.
std::pair<Vec3, Vec3> tangent_basis(const Vec3& d) {
  const Vec3 helper = std::abs(d.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 e1 = d.cross(helper).normalized();
  return {e1, d.cross(e1)};
}

// Sampson distance of a correspondence to x1^T F x0 = 0 (first-order geometric error).
double sampson(const Eigen::Matrix3d& F, const Vec2& x0, const Vec2& x1) {
  const Vec3 a = x0.homogeneous(), b = x1.homogeneous();
  const Vec3 Fa = F * a, Ftb = F.transpose() * b;
  const double e = b.dot(Fa);
  const double denom = Fa.head<2>().squaredNorm() + Ftb.head<2>().squaredNorm();
  return denom > 0 ? std::abs(e) / std::sqrt(denom) : std::numeric_limits<double>::infinity();
}

// Cost of matching cam0 blob k with cam1 blob k (swap = false) or with the other (swap = true):
// the larger Sampson distance of the two LEDs.
double pairing_cost(const Eigen::Matrix3d& F, const std::array<Vec2, 2>& n0,
                    const std::array<Vec2, 2>& n1, bool swap) {
  return std::max(sampson(F, n0[0], n1[swap ? 1 : 0]), sampson(F, n0[1], n1[swap ? 0 : 1]));
}

struct EpipolarFit {
  Eigen::Matrix3d F;  // in normalized coordinates of the nominal cameras
  std::vector<int> inliers;
  std::vector<bool> swap;  // per frame
  std::vector<int> ambiguous;  // both pairings fit: the wand lay in an epipolar plane
};

// Counts the frames whose better pairing fits F within `threshold` (normalized units) and
// whose other pairing does not fit as well, i.e. the frames whose LED identity F decides.
EpipolarFit classify(const Eigen::Matrix3d& F, const std::vector<std::array<Vec2, 2>>& n0,
                     const std::vector<std::array<Vec2, 2>>& n1, double threshold) {
  EpipolarFit fit{F, {}, std::vector<bool>(n0.size(), false), {}};
  for (size_t i = 0; i < n0.size(); ++i) {
    const double straight = pairing_cost(F, n0[i], n1[i], false);
    const double swapped = pairing_cost(F, n0[i], n1[i], true);
    fit.swap[i] = swapped < straight;
    const double best = std::min(straight, swapped), other = std::max(straight, swapped);
    if (best < threshold && other >= threshold) fit.inliers.push_back(static_cast<int>(i));
    if (other < threshold) fit.ambiguous.push_back(static_cast<int>(i));
  }
  return fit;
}

Result<Eigen::Matrix3d> refit(const EpipolarFit& fit, const std::vector<std::array<Vec2, 2>>& n0,
                              const std::vector<std::array<Vec2, 2>>& n1) {
  std::vector<Vec2> a, b;
  for (int i : fit.inliers) {
    const bool s = fit.swap[static_cast<size_t>(i)];
    a.push_back(n0[static_cast<size_t>(i)][0]);
    b.push_back(n1[static_cast<size_t>(i)][s ? 1 : 0]);
    a.push_back(n0[static_cast<size_t>(i)][1]);
    b.push_back(n1[static_cast<size_t>(i)][s ? 0 : 1]);
  }
  return fundamental_8point(a, b);
}

// Robust epipolar geometry with unknown LED identities: each sample of 4 frames is tried with
// all 16 pairings, one of which is right when the 4 frames are clean.
Result<EpipolarFit> robust_epipolar(const std::vector<std::array<Vec2, 2>>& n0,
                                    const std::vector<std::array<Vec2, 2>>& n1, double threshold) {
  std::mt19937_64 rng(0x46495245u);  // fixed seed: calibration is deterministic
  std::uniform_int_distribution<size_t> pick(0, n0.size() - 1);
  constexpr int kSamples = 48;
  EpipolarFit best{Eigen::Matrix3d::Zero(), {}, {}, {}};
  for (int s = 0; s < kSamples; ++s) {
    size_t idx[4];
    for (int k = 0; k < 4; ++k) {
      bool repeated;
      do {
        idx[k] = pick(rng);
        repeated = std::find(idx, idx + k, idx[k]) != idx + k;
      } while (repeated);
    }
    for (int mask = 0; mask < 16; ++mask) {
      std::vector<Vec2> a, b;
      for (int k = 0; k < 4; ++k) {
        const bool swap = (mask >> k) & 1;
        a.push_back(n0[idx[k]][0]);
        b.push_back(n1[idx[k]][swap ? 1 : 0]);
        a.push_back(n0[idx[k]][1]);
        b.push_back(n1[idx[k]][swap ? 0 : 1]);
      }
      const Result<Eigen::Matrix3d> F = fundamental_8point(a, b);
      if (!F) continue;
      EpipolarFit fit = classify(*F, n0, n1, threshold);
      if (fit.inliers.size() > best.inliers.size()) best = std::move(fit);
    }
  }
  if (best.inliers.size() < 8)
    return Result<EpipolarFit>::failure(
        "no epipolar geometry fits the wand observations (" + std::to_string(best.inliers.size()) +
        " consistent frames, at least 8 needed): degenerate motion or unmatched frames");
  // Local optimization: refit on all inliers until the inlier set settles.
  for (int round = 0; round < 4; ++round) {
    const Result<Eigen::Matrix3d> F = refit(best, n0, n1);
    if (!F)
      return Result<EpipolarFit>::failure("degenerate motion: " + F.error());
    EpipolarFit fit = classify(*F, n0, n1, threshold);
    const bool settled = fit.inliers == best.inliers;
    if (fit.inliers.size() < best.inliers.size()) break;
    best = std::move(fit);
    if (settled) break;
  }
  return best;
}

// --- bundle adjustment ---

struct Projection {
  Vec2 pixel;
  Eigen::Matrix<double, 2, kIntrinsicParams> d_intrinsics;
  Eigen::Matrix<double, 2, 3> d_camera_point;  // derivative by the point in camera coordinates
};

Projection project_with_jacobian(const Intrinsics& K, const Vec3& Xc) {
  const double iz = 1.0 / Xc.z();
  const double x = Xc.x() * iz, y = Xc.y() * iz;
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (K.k1 + r2 * K.k2);
  const double dradial_dr2 = K.k1 + 2.0 * K.k2 * r2;
  Projection p;
  p.pixel = {K.fx * radial * x + K.cx, K.fy * radial * y + K.cy};
  p.d_intrinsics << radial * x, 0, 1, 0, K.fx * x * r2,  //
      0, radial * y, 0, 1, K.fy * y * r2;
  Eigen::Matrix2d d_normalized;
  d_normalized << K.fx * (radial + 2 * x * x * dradial_dr2), K.fx * 2 * x * y * dradial_dr2,
      K.fy * 2 * x * y * dradial_dr2, K.fy * (radial + 2 * y * y * dradial_dr2);
  Eigen::Matrix<double, 2, 3> d_perspective;
  d_perspective << iz, 0, -x * iz, 0, iz, -y * iz;
  p.d_camera_point = d_normalized * d_perspective;
  return p;
}

Intrinsics updated(Intrinsics K, const double* d) {
  K.fx += d[0];
  K.fy += d[1];
  K.cx += d[2];
  K.cy += d[3];
  K.k1 += d[4];
  return K;
}

std::array<Vec3, 2> wand_points(const Wand& w, double half_length) {
  return {w.centre + half_length * w.direction, w.centre - half_length * w.direction};
}

// Calls visit(frame index, camera, pixel residual) for every blob, always in the same order, so
// that sums over the residuals are reproducible to the bit.
template <typename Visit>
void for_each_residual(const Model& m, const std::vector<Frame>& frames, double half_length, Visit&& visit) {
  const Camera c0{m.K[0], Eigen::Matrix3d::Identity(), Vec3::Zero()};
  const Camera c1{m.K[1], m.R1, m.t1};
  for (size_t i = 0; i < frames.size(); ++i) {
    const auto X = wand_points(m.wands[i], half_length);
    for (int k = 0; k < 2; ++k) {
      visit(i, 0, Vec2(c0.project(X[k]) - frames[i].cam0[k]));
      visit(i, 1, Vec2(c1.project(X[k]) - frames[i].cam1[k]));
    }
  }
}

double total_cost(const Model& m, const std::vector<Frame>& frames, double half_length) {
  double sum = 0;
  for_each_residual(m, frames, half_length, [&](size_t, int, const Vec2& r) { sum += r.squaredNorm(); });
  return sum;
}

// Per coordinate (x and y counted separately) over `frames` frames of 2 blobs in 2 cameras.
double rms_per_coordinate(double cost, size_t frames) {
  return std::sqrt(cost / (8.0 * static_cast<double>(frames)));
}

struct NormalEquations {
  CameraBlock Hcc = CameraBlock::Zero();
  CameraVector gc = CameraVector::Zero();
  std::vector<WandBlock> Hww;
  std::vector<CrossBlock> Hcw;
  std::vector<WandVector> gw;
};

NormalEquations build_normal_equations(const Model& m, const std::vector<Frame>& frames,
                                       double half_length) {
  NormalEquations ne;
  ne.Hww.assign(frames.size(), WandBlock::Zero());
  ne.Hcw.assign(frames.size(), CrossBlock::Zero());
  ne.gw.assign(frames.size(), WandVector::Zero());
  for (size_t i = 0; i < frames.size(); ++i) {
    const Wand& w = m.wands[i];
    const auto X = wand_points(w, half_length);
    const auto [e1, e2] = tangent_basis(w.direction);
    for (int k = 0; k < 2; ++k) {
      // dX/d(wand params): centre moves both LEDs, the direction moves them oppositely.
      Eigen::Matrix<double, 3, kWandParams> dX;
      const double h = k == 0 ? half_length : -half_length;
      dX << Eigen::Matrix3d::Identity(), h * e1, h * e2;
      for (int cam = 0; cam < 2; ++cam) {
        const Vec3 Xc = cam == 0 ? X[k] : Vec3(m.R1 * X[k] + m.t1);
        const Projection p = project_with_jacobian(m.K[cam], Xc);
        const Vec2 r = p.pixel - (cam == 0 ? frames[i].cam0[k] : frames[i].cam1[k]);
        Eigen::Matrix<double, 2, kCameraParams> Jc = Eigen::Matrix<double, 2, kCameraParams>::Zero();
        Jc.block<2, kIntrinsicParams>(0, cam * kIntrinsicParams) = p.d_intrinsics;
        Eigen::Matrix<double, 2, kWandParams> Jw;
        if (cam == 0) {
          Jw = p.d_camera_point * dX;
        } else {
          // Xc = exp(w) R1 X + t1: d/dw = -[R1 X]x, d/dt1 = I.
          const Vec3 RX = m.R1 * X[k];
          Eigen::Matrix3d minus_skew;
          minus_skew << 0, RX.z(), -RX.y(), -RX.z(), 0, RX.x(), RX.y(), -RX.x(), 0;
          Jc.block<2, 3>(0, 2 * kIntrinsicParams) = p.d_camera_point * minus_skew;
          Jc.block<2, 3>(0, 2 * kIntrinsicParams + 3) = p.d_camera_point;
          Jw = p.d_camera_point * m.R1 * dX;
        }
        ne.Hcc.noalias() += Jc.transpose() * Jc;
        ne.gc.noalias() += Jc.transpose() * r;
        ne.Hww[i].noalias() += Jw.transpose() * Jw;
        ne.Hcw[i].noalias() += Jc.transpose() * Jw;
        ne.gw[i].noalias() += Jw.transpose() * r;
      }
    }
  }
  return ne;
}

struct Step {
  CameraVector dc;
  std::vector<WandVector> dw;
  bool ok;
};

// Solves the damped normal equations by the Schur complement on the 5 x 5 wand blocks.
Step solve_damped(const NormalEquations& ne, double lambda) {
  Step s{CameraVector::Zero(), std::vector<WandVector>(ne.Hww.size()), false};
  CameraBlock S = ne.Hcc;
  S.diagonal() *= 1.0 + lambda;
  CameraVector rhs = -ne.gc;
  std::vector<Eigen::LDLT<WandBlock>> wand_solvers;
  wand_solvers.reserve(ne.Hww.size());
  for (size_t i = 0; i < ne.Hww.size(); ++i) {
    WandBlock H = ne.Hww[i];
    H.diagonal() *= 1.0 + lambda;
    H.diagonal().array() += 1e-12;
    wand_solvers.emplace_back(H);
    const CrossBlock HcwHinv = wand_solvers.back().solve(ne.Hcw[i].transpose()).transpose();
    S.noalias() -= HcwHinv * ne.Hcw[i].transpose();
    rhs.noalias() += HcwHinv * ne.gw[i];
  }
  // Jacobi scaling: focal lengths, k1 and translations differ by orders of magnitude.
  const CameraVector scale = S.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const CameraBlock Sn = scale.asDiagonal() * S * scale.asDiagonal();
  const Eigen::LDLT<CameraBlock> ldlt(Sn);
  if (ldlt.info() != Eigen::Success) return s;
  s.dc = scale.asDiagonal() * ldlt.solve(scale.asDiagonal() * rhs);
  if (!s.dc.allFinite()) return s;
  for (size_t i = 0; i < ne.Hww.size(); ++i)
    s.dw[i] = wand_solvers[i].solve(-ne.gw[i] - ne.Hcw[i].transpose() * s.dc);
  s.ok = true;
  return s;
}

Model apply_step(const Model& m, const Step& s) {
  Model n = m;
  n.K[0] = updated(m.K[0], s.dc.data());
  n.K[1] = updated(m.K[1], s.dc.data() + kIntrinsicParams);
  n.R1 = rotation_from_vector(s.dc.segment<3>(2 * kIntrinsicParams)) * m.R1;
  n.t1 = m.t1 + s.dc.segment<3>(2 * kIntrinsicParams + 3);
  for (size_t i = 0; i < m.wands.size(); ++i) {
    const auto [e1, e2] = tangent_basis(m.wands[i].direction);
    n.wands[i].centre = m.wands[i].centre + s.dw[i].head<3>();
    n.wands[i].direction = (m.wands[i].direction + s.dw[i](3) * e1 + s.dw[i](4) * e2).normalized();
  }
  return n;
}

struct Adjustment {
  Model model;
  double cost;
  int iterations;
};

// Called with the starting point (iteration 0) and after each accepted step.
using StepObserver = std::function<void(const Model&, double cost, int iteration)>;

// Levenberg-Marquardt with Marquardt's diagonal damping.
Adjustment bundle_adjust(Model m, const std::vector<Frame>& frames, double half_length,
                         int max_iterations, const StepObserver& on_step) {
  double cost = total_cost(m, frames, half_length);
  double lambda = 1e-4;
  int it = 0;
  on_step(m, cost, it);
  NormalEquations ne = build_normal_equations(m, frames, half_length);
  while (it < max_iterations) {
    ++it;
    const Step s = solve_damped(ne, lambda);
    if (!s.ok) {
      lambda *= 10;
      if (lambda > 1e12) break;
      continue;
    }
    // Parameter tolerance: a step this small changes nothing measurable (noise-free data
    // reaches it at the rounding floor, where no step decreases the cost any more).
    const CameraVector current = (CameraVector() << m.K[0].fx, m.K[0].fy, m.K[0].cx, m.K[0].cy,
                                  m.K[0].k1, m.K[1].fx, m.K[1].fy, m.K[1].cx, m.K[1].cy, m.K[1].k1,
                                  0, 0, 0, m.t1).finished();
    if (s.dc.norm() <= 1e-12 * current.norm()) break;
    const Model candidate = apply_step(m, s);
    const double candidate_cost = total_cost(candidate, frames, half_length);
    if (std::isfinite(candidate_cost) && candidate_cost < cost) {
      const double decrease = (cost - candidate_cost) / cost;
      m = candidate;
      cost = candidate_cost;
      on_step(m, cost, it);
      lambda = std::max(lambda / 5, 1e-12);
      if (decrease < 1e-12) break;
      ne = build_normal_equations(m, frames, half_length);
    } else {
      lambda *= 5;
      if (lambda > 1e12) break;
    }
  }
  return {std::move(m), cost, it};
}

// Largest coordinate residual of each frame.
std::vector<double> frame_residuals(const Model& m, const std::vector<Frame>& frames, double half_length) {
  std::vector<double> worst(frames.size(), 0.0);
  for_each_residual(m, frames, half_length, [&](size_t i, int, const Vec2& r) {
    worst[i] = std::max(worst[i], r.cwiseAbs().maxCoeff());
  });
  return worst;
}

// Reports the adjustment's state to CalibrationOptions::on_iteration. The per-camera sums are
// computed here only, so an unobserved calibration does no extra work.
CalibrationProgress progress(const Model& m, const std::vector<Frame>& frames, double half_length, double cost,
                             int iteration, bool finished) {
  std::array<double, 2> camera_cost{0.0, 0.0};
  for_each_residual(m, frames, half_length,
                    [&](size_t, int cam, const Vec2& r) { camera_cost[cam] += r.squaredNorm(); });
  CalibrationProgress p;
  p.iteration = iteration;
  p.frames = static_cast<int>(frames.size());
  p.reprojection_rms_px = rms_per_coordinate(cost, frames.size());
  // A camera has 4 of a frame's 8 coordinates.
  for (int c = 0; c < 2; ++c) p.camera_rms_px[c] = rms_per_coordinate(2.0 * camera_cost[c], frames.size());
  p.finished = finished;
  return p;
}

double median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

Result<CalibrationResult> calibrate_wand(std::span<const WandObservation> obs,
                                         const CalibrationOptions& o) {
  using R = Result<CalibrationResult>;
  const std::string what = "wand calibration: ";
  if (!std::isfinite(o.wand_length_m) || !(o.wand_length_m > 0))
    return R::failure(what + "the wand length must be a positive number of metres, got " +
                      std::to_string(o.wand_length_m));
  for (const Intrinsics* K : {&o.nominal0, &o.nominal1})
    if (!std::isfinite(K->fx) || !std::isfinite(K->fy) || !std::isfinite(K->cx) ||
        !std::isfinite(K->cy) || !std::isfinite(K->k1) || !std::isfinite(K->k2) || !(K->fx > 0) ||
        !(K->fy > 0))
      return R::failure(what + "the nominal intrinsics must be finite with positive focal lengths");
  if (o.max_iterations < 1) return R::failure(what + "max_iterations must be at least 1");

  // A frame is usable when both cameras see two distinct blobs; LEDs closer than a pixel
  // merge into one blob on the device, so such frames cannot be told apart.
  int seen0 = 0, seen1 = 0;
  std::vector<size_t> usable;
  for (size_t i = 0; i < obs.size(); ++i) {
    const bool in0 = finite_pair(obs[i].cam0), in1 = finite_pair(obs[i].cam1);
    seen0 += in0;
    seen1 += in1;
    if (in0 && in1 && (obs[i].cam0[0] - obs[i].cam0[1]).norm() >= 1.0 &&
        (obs[i].cam1[0] - obs[i].cam1[1]).norm() >= 1.0)
      usable.push_back(i);
  }
  if (seen0 == 0 || seen1 == 0)
    return R::failure(what + "the wand is never seen by camera " + (seen0 == 0 ? "0" : "1") + " (" +
                      std::to_string(obs.size()) + " observations)");
  if (usable.size() < 8)
    return R::failure(what + std::to_string(usable.size()) +
                      " usable observations (both LEDs seen by both cameras), at least 8 needed");

  const Camera nominal0{o.nominal0, Eigen::Matrix3d::Identity(), Vec3::Zero()};
  const Camera nominal1{o.nominal1, Eigen::Matrix3d::Identity(), Vec3::Zero()};
  std::vector<std::array<Vec2, 2>> n0(usable.size()), n1(usable.size());
  for (size_t j = 0; j < usable.size(); ++j)
    for (int k = 0; k < 2; ++k) {
      n0[j][k] = nominal0.undistort_normalized(obs[usable[j]].cam0[k]);
      n1[j][k] = nominal1.undistort_normalized(obs[usable[j]].cam1[k]);
    }

  // Generous: the nominal intrinsics leave distortion unmodelled until the adjustment.
  const double focal = 0.5 * (o.nominal0.fx + o.nominal1.fx);
  const Result<EpipolarFit> epipolar = robust_epipolar(n0, n1, 6.0 / focal);
  if (!epipolar) return R::failure(what + epipolar.error());

  std::vector<Vec2> m0, m1;
  for (int i : epipolar->inliers) {
    const bool s = epipolar->swap[static_cast<size_t>(i)];
    m0.push_back(n0[static_cast<size_t>(i)][0]);
    m1.push_back(n1[static_cast<size_t>(i)][s ? 1 : 0]);
    m0.push_back(n0[static_cast<size_t>(i)][1]);
    m1.push_back(n1[static_cast<size_t>(i)][s ? 0 : 1]);
  }
  const Result<RelativePose> pose = recover_pose(epipolar->F, m0, m1);
  if (!pose) return R::failure(what + "degenerate motion: " + pose.error());

  // Unit-baseline reconstruction; its wand lengths give the metric scale.
  const Camera unit0 = nominal0, unit1{o.nominal1, pose->R, pose->t};
  struct Initial {
    Frame frame;
    Vec3 A, B;
  };
  auto reconstruct = [&](const WandObservation& ob, bool swap) -> std::optional<Initial> {
    Initial in{{ob.cam0, {ob.cam1[swap ? 1 : 0], ob.cam1[swap ? 0 : 1]}}, Vec3::Zero(), Vec3::Zero()};
    const Triangulation a = triangulate(unit0, unit1, in.frame.cam0[0], in.frame.cam1[0],
                                        TriangulationMethod::Optimal, 1e9);
    const Triangulation b = triangulate(unit0, unit1, in.frame.cam0[1], in.frame.cam1[1],
                                        TriangulationMethod::Optimal, 1e9);
    if (!a.accepted || !b.accepted) return std::nullopt;
    in.A = a.X;
    in.B = b.X;
    return in;
  };
  std::vector<Initial> initial;
  std::vector<double> lengths;
  for (int i : epipolar->inliers) {
    const auto in = reconstruct(obs[usable[static_cast<size_t>(i)]], epipolar->swap[static_cast<size_t>(i)]);
    if (!in) continue;
    initial.push_back(*in);
    lengths.push_back((in->A - in->B).norm());
  }
  if (initial.size() < 8)
    return R::failure(what + "degenerate motion: only " + std::to_string(initial.size()) +
                      " frames triangulate in front of both cameras");
  const double scale = o.wand_length_m / median(lengths);
  if (!std::isfinite(scale) || !(scale > 0))
    return R::failure(what + "degenerate motion: the wand's reconstructed length is zero");
  auto length_error = [&](const Initial& in) {
    return std::abs(scale * (in.A - in.B).norm() / o.wand_length_m - 1.0);
  };
  // A wand lying in an epipolar plane fits both LED pairings; the wand length tells them apart
  // when one pairing is clearly right and the other clearly wrong.
  for (int i : epipolar->ambiguous) {
    const WandObservation& ob = obs[usable[static_cast<size_t>(i)]];
    const auto straight = reconstruct(ob, false), swapped = reconstruct(ob, true);
    const double e_straight = straight ? length_error(*straight) : 1e300;
    const double e_swapped = swapped ? length_error(*swapped) : 1e300;
    if (std::min(e_straight, e_swapped) < 0.1 && std::max(e_straight, e_swapped) > 0.25)
      initial.push_back(e_straight < e_swapped ? *straight : *swapped);
  }

  Model model{{o.nominal0, o.nominal1}, pose->R, scale * pose->t, {}};
  // Frames whose unit-baseline length is far off are mismatched; they would only slow the start.
  std::vector<Frame> frames;
  for (const Initial& in : initial) {
    if (length_error(in) > 0.25) continue;
    frames.push_back(in.frame);
    model.wands.push_back({scale * 0.5 * (in.A + in.B), (in.A - in.B).normalized()});
  }
  if (frames.size() < 8)
    return R::failure(what + "degenerate motion: only " + std::to_string(frames.size()) +
                      " frames give a consistent wand length");

  const double half_length = 0.5 * o.wand_length_m;
  // Iteration numbers run on through the adjustment resumed without the outlying frames.
  int iterations = 0;
  const StepObserver on_step = [&](const Model& m, double cost, int iteration) {
    if (o.on_iteration) o.on_iteration(progress(m, frames, half_length, cost, iterations + iteration, false));
  };
  Adjustment adj = bundle_adjust(std::move(model), frames, half_length, o.max_iterations, on_step);
  iterations = adj.iterations;

  // One pass of outlier removal: a frame whose worst residual is far beyond the robust spread
  // (mismatched LEDs, a reflection, a bad time alignment) is dropped and the adjustment resumed.
  {
    const std::vector<double> worst = frame_residuals(adj.model, frames, half_length);
    const double spread = 1.4826 * median(worst);
    const double limit = std::max(4.0 * spread, 1.0);
    std::vector<Frame> inlier_frames;
    Model inlier_model = adj.model;
    inlier_model.wands.clear();
    for (size_t i = 0; i < frames.size(); ++i)
      if (worst[i] <= limit) {
        inlier_frames.push_back(frames[i]);
        inlier_model.wands.push_back(adj.model.wands[i]);
      }
    if (inlier_frames.size() < frames.size()) {
      if (inlier_frames.size() < 8)
        return R::failure(what + "only " + std::to_string(inlier_frames.size()) +
                          " observations fit the adjusted model");
      frames = std::move(inlier_frames);
      adj = bundle_adjust(std::move(inlier_model), frames, half_length,
                          std::max(1, o.max_iterations - iterations), on_step);
      iterations += adj.iterations;
    }
  }
  if (o.on_iteration) o.on_iteration(progress(adj.model, frames, half_length, adj.cost, iterations, true));

  // A wand that only translates, or stays in one plane, leaves the cameras (nearly) undetermined
  // even when the residuals are small. The reduced camera system's inverse is their covariance:
  // refuse when a focal length's standard deviation exceeds 1 %. The noise is floored at the
  // device's integer rounding (1/sqrt(12) px), so noise-free synthetic data is judged the same.
  {
    const NormalEquations ne = build_normal_equations(adj.model, frames, half_length);
    CameraBlock S = ne.Hcc;
    for (size_t i = 0; i < frames.size(); ++i)
      S -= ne.Hcw[i] * ne.Hww[i].ldlt().solve(ne.Hcw[i].transpose());
    const CameraVector scale_s = S.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
    const Eigen::LDLT<CameraBlock> ldlt(scale_s.asDiagonal() * S * scale_s.asDiagonal());
    const CameraBlock covariance_unit =
        scale_s.asDiagonal() * ldlt.solve(CameraBlock::Identity()) * scale_s.asDiagonal();
    const double sigma = std::max(rms_per_coordinate(adj.cost, frames.size()), 1.0 / std::sqrt(12.0));
    double worst_relative = 0;
    for (int c = 0; c < 2; ++c)
      for (int k = 0; k < 2; ++k) {
        const int index = c * kIntrinsicParams + k;
        const double focal = k == 0 ? adj.model.K[c].fx : adj.model.K[c].fy;
        const double relative = sigma * std::sqrt(covariance_unit(index, index)) / std::abs(focal);
        worst_relative = std::isfinite(relative) ? std::max(worst_relative, relative)
                                                 : std::numeric_limits<double>::infinity();
      }
    if (ldlt.info() != Eigen::Success || !(worst_relative < 0.01))
      return R::failure(what + "degenerate motion: the wand poses leave the focal lengths "
                        "undetermined (standard deviation " + std::to_string(100 * worst_relative) +
                        " %); wave the wand through the whole volume, turning it");
  }
  if (!(adj.model.K[0].fx > 0) || !(adj.model.K[1].fx > 0) || !std::isfinite(adj.cost))
    return R::failure(what + "the bundle adjustment diverged");

  CalibrationResult out;
  out.cam0 = Camera{adj.model.K[0], Eigen::Matrix3d::Identity(), Vec3::Zero()};
  out.cam1 = Camera{adj.model.K[1], adj.model.R1, adj.model.t1};
  out.reprojection_rms_px = rms_per_coordinate(adj.cost, frames.size());
  out.reprojection_rms_2d_px = rms_per_coordinate(2.0 * adj.cost, frames.size());
  double length_sq = 0;
  for (const Frame& f : frames) {
    Vec3 X[2];
    for (int k = 0; k < 2; ++k)
      X[k] = triangulate(out.cam0, out.cam1, f.cam0[k], f.cam1[k], TriangulationMethod::Optimal, 1e9).X;
    const double e = (X[0] - X[1]).norm() - o.wand_length_m;
    length_sq += e * e;
  }
  out.wand_length_error_mm = 1000.0 * std::sqrt(length_sq / static_cast<double>(frames.size()));
  out.observations_used = static_cast<int>(frames.size());
  out.observations_rejected = static_cast<int>(obs.size()) - out.observations_used;
  out.iterations = iterations;
  return out;
}

}  // namespace fire::tracking
