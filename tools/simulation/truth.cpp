// The truth a simulated session logs, read back, and the tracker's and the calibration's errors against it; the
// simulated rig's true cameras as a rig file.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>

#include "systems/tracking/registration.hpp"
#include "systems/tracking/rig_io.hpp"
#include "tools/simulation/simulate.hpp"

namespace fire::simulation {
using namespace tracking;  // the cameras, calibration and tracking this simulation feeds and checks


SessionTruth read_session_truth(std::span<const InputEvent> events) {
  SessionTruth truth;
  std::array<bool, 2> camera_seen{};
  std::array<bool, 2> clock_seen{};
  auto finite = [](const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double d) { return std::isfinite(d); });
  };
  auto device_of = [](double d) { return d == 0.0 ? 0 : d == 1.0 ? 1 : -1; };
  std::array<uint32_t, 2> report_line{};  // each device's latest report: a pen truth follows its report
  for (const InputEvent& e : events) {
    if (e.kind == EventKind::Hid && (e.device == 0 || e.device == 1)) report_line[size_t(e.device)] = e.line;
    if (e.kind == EventKind::Truth) {
      const std::vector<double>& v = e.values;
      const int d = v.empty() ? -1 : device_of(v[0]);
      if (e.name == "camera") {
        if (v.size() != 19 || !finite(v) || d < 0) {
          ++truth.rejected_lines;
          continue;
        }
        Camera& c = truth.cameras[d];
        c.K = Intrinsics{.fx = v[1], .fy = v[2], .cx = v[3], .cy = v[4], .k1 = v[5], .k2 = v[6]};
        for (int r = 0; r < 3; ++r)
          for (int k = 0; k < 3; ++k) c.R(r, k) = v[7 + 3 * r + k];
        c.t = Vec3(v[16], v[17], v[18]);
        camera_seen[d] = true;
      } else if (e.name == "clock") {
        if (v.size() != 5 || !finite(v) || d < 0) {
          ++truth.rejected_lines;
          continue;
        }
        truth.latency_us[d] = v[3];
        clock_seen[d] = true;
      } else if (e.name == "pen") {
        if (v.size() != 8 || !finite(v) || d < 0) {
          ++truth.rejected_lines;
          continue;
        }
        truth.pen.push_back({d, e.t_us, report_line[size_t(d)], Vec3(v[2], v[3], v[4]), v[5] != 0.0, v[6], v[7]});
      }
    } else if (e.kind == EventKind::Meta) {
      if (e.name == "nominal_intrinsics") {
        std::vector<double> v;
        const char* p = e.text.c_str();
        const char* end = p + e.text.size();
        while (p < end) {
          while (p < end && *p == ' ') ++p;
          if (p == end) break;
          double x;
          const auto r = std::from_chars(p, end, x);
          if (r.ec != std::errc()) {
            v.clear();
            break;
          }
          v.push_back(x);
          p = r.ptr;
        }
        const int d = v.empty() ? -1 : device_of(v[0]);
        if (v.size() != 7 || !finite(v) || d < 0 || !(v[1] > 0) || !(v[2] > 0)) {
          ++truth.rejected_lines;
          continue;
        }
        truth.nominal[d] = Intrinsics{.fx = v[1], .fy = v[2], .cx = v[3], .cy = v[4], .k1 = v[5], .k2 = v[6]};
        truth.has_nominal[d] = true;
      } else if (e.name == "wand_length_m") {
        double x = 0;
        const auto r = std::from_chars(e.text.data(), e.text.data() + e.text.size(), x);
        if (r.ec != std::errc() || r.ptr != e.text.data() + e.text.size() || !std::isfinite(x) || !(x > 0)) {
          ++truth.rejected_lines;
          continue;
        }
        truth.wand_length_m = x;
        truth.has_wand_length = true;
      }
    }
  }
  truth.has_cameras = camera_seen[0] && camera_seen[1];
  truth.has_clocks = clock_seen[0] && clock_seen[1];
  return truth;
}

namespace {

void accumulate(ErrorStats& s, double err_m) {
  const double mm = err_m * 1e3;
  ++s.samples;
  s.rms_mm += mm * mm;  // the sum of squares until finish()
  s.max_mm = std::max(s.max_mm, mm);
}

void finish(ErrorStats& s) { s.rms_mm = s.samples ? std::sqrt(s.rms_mm / static_cast<double>(s.samples)) : 0.0; }

double angle_deg(const Eigen::Matrix3d& R) {
  return std::acos(std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

}  // namespace

Result<PenAccuracy> evaluate_pen_accuracy(const PenTrack& track, const SessionTruth& truth,
                                          double settle_s) {
  if (!truth.has_cameras)
    return Result<PenAccuracy>::failure("the log holds no camera truth (was it written by fire simulate sketch?)");
  std::vector<const PenTruth*> by_time;  // camera 0's pen truths, in arrival order
  for (const PenTruth& p : truth.pen)
    if (p.device == 0) by_time.push_back(&p);
  const Camera& c0 = truth.cameras[0];
  enum class Kind { Static, Settling, Dynamic };
  struct Compared {
    Vec3 filtered, truth;
    Kind kind;
  };
  std::vector<Compared> compared;
  // Consecutive static samples of one stroke form a hold: one rest point for the registration.
  std::vector<Vec3> hold_measured, hold_true;
  std::vector<int> hold_count;
  bool in_hold = false;
  uint32_t hold_stroke = 0;
  PenAccuracy acc;
  for (const PenSample& s : track.samples) {
    const int64_t key = s.cam0_arrival_us;
    auto it = std::lower_bound(by_time.begin(), by_time.end(), key,
                               [](const PenTruth* p, int64_t t) { return p->t_us < t; });
    // Reports delivered together (a burst) share their arrival: their lines in the log tell them apart.
    if (s.cam0_line != 0)
      for (auto same = it; same != by_time.end() && (*same)->t_us == key; ++same)
        if ((*same)->report_line == s.cam0_line) {
          it = same;
          break;
        }
    if (it == by_time.end() || (*it)->t_us != key) {
      ++acc.unmatched;
      continue;
    }
    const PenTruth& p = **it;
    if (!p.lit) {
      ++acc.phantom;
      continue;
    }
    const Vec3 X = c0.R * p.position + c0.t;
    const double filtered = (s.filtered - X).norm(), raw = (s.raw - X).norm();
    const Kind kind = p.speed_m_s > 0 ? Kind::Dynamic : p.still_s >= settle_s ? Kind::Static : Kind::Settling;
    compared.push_back({s.filtered, X, kind});
    if (kind == Kind::Dynamic) {
      accumulate(acc.dynamic_filtered, filtered);
      accumulate(acc.dynamic_raw, raw);
    } else if (kind == Kind::Static) {
      accumulate(acc.static_filtered, filtered);
      accumulate(acc.static_raw, raw);
      if (!in_hold || hold_stroke != s.stroke) {
        hold_measured.push_back(Vec3::Zero());
        hold_true.push_back(Vec3::Zero());
        hold_count.push_back(0);
      }
      hold_measured.back() += s.filtered;
      hold_true.back() += X;
      ++hold_count.back();
      hold_stroke = s.stroke;
    } else {
      accumulate(acc.settling_filtered, filtered);
    }
    in_hold = kind == Kind::Static;
  }
  for (ErrorStats* e : {&acc.static_filtered, &acc.settling_filtered, &acc.dynamic_filtered, &acc.static_raw, &acc.dynamic_raw})
    finish(*e);
  for (size_t h = 0; h < hold_count.size(); ++h) {
    hold_measured[h] /= hold_count[h];
    hold_true[h] /= hold_count[h];
  }
  if (const Result<RigidTransform> reg = register_rigid(hold_measured, hold_true); reg) {
    acc.registered = true;
    acc.registration_points = hold_count.size();
    acc.registration_rms_mm = reg->rms_residual * 1e3;
    for (const Compared& c : compared) {
      const double e = (reg->R * c.filtered + reg->t - c.truth).norm();
      if (c.kind == Kind::Static) accumulate(acc.registered_static, e);
      if (c.kind == Kind::Dynamic) accumulate(acc.registered_dynamic, e);
    }
    finish(acc.registered_static);
    finish(acc.registered_dynamic);
  }
  return acc;
}

Result<RigErrors> compare_rig(const CalibrationResult& rig, const SessionTruth& truth) {
  if (!truth.has_cameras) return Result<RigErrors>::failure("the log holds no camera truth");
  const Camera& t0 = truth.cameras[0];
  const Camera& t1 = truth.cameras[1];
  // Camera 1 relative to camera 0, for the truth and for the rig (whose camera 0 need not be at the origin).
  const Eigen::Matrix3d R_true = t1.R * t0.R.transpose();
  const Vec3 b_true = t1.t - R_true * t0.t;
  const Eigen::Matrix3d R_cal = rig.cam1.R * rig.cam0.R.transpose();
  const Vec3 b_cal = rig.cam1.t - R_cal * rig.cam0.t;
  RigErrors e;
  e.baseline_error_mm = (b_cal.norm() - b_true.norm()) * 1e3;
  e.rotation_error_deg = angle_deg(R_cal.transpose() * R_true);
  e.direction_error_deg =
      std::acos(std::clamp(b_cal.normalized().dot(b_true.normalized()), -1.0, 1.0)) * 180.0 / std::numbers::pi;
  const Camera* cal[2] = {&rig.cam0, &rig.cam1};
  for (int d = 0; d < 2; ++d) {
    const Intrinsics& k = cal[d]->K;
    const Intrinsics& t = truth.cameras[d].K;
    e.focal_error_px[d] = 0.5 * ((k.fx - t.fx) + (k.fy - t.fy));
    e.principal_point_error_px[d] = std::hypot(k.cx - t.cx, k.cy - t.cy);
    e.k1_error[d] = k.k1 - t.k1;
  }
  return e;
}

Result<std::string> true_rig_json(const RigOptions& o) {
  Result<SimulatedRig> rig = make_simulated_rig(o);
  if (!rig) return Result<std::string>::failure(rig.error());
  CalibrationResult calibrated;
  calibrated.cam0 = rig->cameras[0];
  calibrated.cam1 = rig->cameras[1];
  calibrated.time_offset_us = o.clock_offset_ms * 1e3;
  return rig_to_json(calibrated);
}

}  // namespace fire::simulation
