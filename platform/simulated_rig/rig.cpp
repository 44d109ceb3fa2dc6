// The simulated rig: two Wii Remotes' true cameras and clocks, and both run over a scene into a session of
// report bytes in host arrival order with the truth beside them (simulated_rig.hpp's time model).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include "engine/ir_report.hpp"
#include "platform/simulated_rig/simulated_rig_detail.hpp"

namespace fire::simulation {
using namespace tracking;  // the camera model (engine/camera.hpp) the rig projects with
using namespace detail;

namespace {

constexpr double kMergeDistancePx = 8.0;  // one pixel of the 128 x 96 sensor
constexpr int kStrayDevice = 1;
constexpr int kStraySource = 100;

Eigen::Matrix3d look_at(const Vec3& centre, const Vec3& target, double roll_rad) {
  const Vec3 z = (target - centre).normalized();
  const Vec3 y = (Vec3::UnitY() - Vec3::UnitY().dot(z) * z).normalized();
  const Vec3 x = y.cross(z);
  Eigen::Matrix3d R;
  R.row(0) = x;
  R.row(1) = y;
  R.row(2) = z;
  return Eigen::AngleAxisd(roll_rad, Vec3::UnitZ()).toRotationMatrix() * R;
}

Status check_rig(const RigOptions& o) {
  const std::pair<const char*, double> named[] = {
      {"baseline", o.baseline_m},   {"distance", o.target_distance_m}, {"focal", o.focal_px},
      {"focal error", o.focal_error}, {"k1", o.k1},                   {"k2", o.k2},
      {"noise", o.noise_px},        {"rate", o.rate_hz},              {"drift", o.drift_ppm},
      {"latency", o.latency_ms},    {"clock offset", o.clock_offset_ms}, {"jitter", o.jitter_ms},
      {"dropout", o.dropout},       {"stray", o.stray},               {"occlusion", o.occlusion_per_s},
      {"burst", o.burst}};
  for (const auto& [name, value] : named)
    if (!std::isfinite(value)) return Status::failure(std::string("the ") + name + " must be a finite number");
  if (!(o.baseline_m > 0) || !(o.target_distance_m > 0)) return Status::failure("baseline and distance must be positive");
  if (!(o.focal_px > 100)) return Status::failure("the focal length must exceed 100 px");
  if (!(std::abs(o.focal_error) < 0.5)) return Status::failure("the focal error must be within (-0.5, 0.5)");
  if (o.noise_px < 0 || o.jitter_ms < 0 || o.occlusion_per_s < 0) return Status::failure("noise, jitter and occlusion rate must not be negative");
  if (!(o.rate_hz >= 1 && o.rate_hz <= 1000)) return Status::failure("the report rate must be within 1..1000 Hz");
  if (!(std::abs(o.drift_ppm) < 10000)) return Status::failure("the drift must be within +-10000 ppm");
  if (o.latency_ms < 0 || o.latency_ms + o.clock_offset_ms < 0) return Status::failure("both cameras' latencies must be non-negative");
  if (!(o.dropout >= 0 && o.dropout < 1)) return Status::failure("dropout must be within [0, 1)");
  if (!(o.burst >= 0 && o.burst < 1)) return Status::failure("burst must be within [0, 1)");
  if (!(o.stray >= 0 && o.stray <= 1)) return Status::failure("stray must be within [0, 1]");
  return Status::success();
}

struct Clock {
  double rate_hz, phase_s, latency_s, jitter_s;
};

struct PendingReport {
  int64_t t_us;
  int device;
  double exposure_s;
  std::vector<uint8_t> bytes;
  SceneSample scene;
};

struct Blob {
  Vec2 px;
  uint8_t size;
  int source;
};

// Slot assignment as the camera does it: an object keeps its slot while it stays in view; a
// newcomer takes the lowest free slot.
struct SlotTracker {
  std::array<int, kIrSlots> owner{-1, -1, -1, -1};
  std::array<IrSlot, kIrSlots> assign(const std::vector<Blob>& blobs) {
    for (int& o : owner)
      if (std::none_of(blobs.begin(), blobs.end(), [&](const Blob& b) { return b.source == o; })) o = -1;
    std::array<IrSlot, kIrSlots> slots{};
    for (const Blob& b : blobs) {
      auto it = std::find(owner.begin(), owner.end(), b.source);
      if (it == owner.end()) it = std::find(owner.begin(), owner.end(), -1);
      if (it == owner.end()) continue;  // the camera tracks four objects at most
      *it = b.source;
      slots[static_cast<size_t>(it - owner.begin())] =
          IrSlot{.seen = true, .x = static_cast<uint16_t>(b.px.x()), .y = static_cast<uint16_t>(b.px.y()), .size = b.size};
    }
    return slots;
  }
};

struct Interval {
  double begin, end;
};

std::vector<Interval> occlusion_intervals(Random& rng, double rate_per_s, double duration_s) {
  std::vector<Interval> out;
  if (rate_per_s <= 0) return out;
  double t = rng.exponential(1.0 / rate_per_s);
  while (t < duration_s) {
    const double len = rng.uniform(0.05, 0.3);
    out.push_back({t, t + len});
    t += len + rng.exponential(1.0 / rate_per_s);
  }
  return out;
}

bool inside(const std::vector<Interval>& intervals, double t) {
  return std::any_of(intervals.begin(), intervals.end(), [&](const Interval& i) { return t >= i.begin && t < i.end; });
}

void add_truth(std::vector<InputEvent>& ev, int64_t t_us, const std::string& name, std::vector<double> values) {
  InputEvent e;
  e.t_us = t_us;
  e.kind = EventKind::Truth;
  e.name = name;
  e.values = std::move(values);
  ev.push_back(std::move(e));
}

std::string rig_options_text(const RigOptions& o) {
  return "baseline_m=" + format_double(o.baseline_m) + " target_distance_m=" + format_double(o.target_distance_m) +
         " focal_px=" + format_double(o.focal_px) + " focal_error=" + format_double(o.focal_error) +
         " k1=" + format_double(o.k1) + " k2=" + format_double(o.k2) + " noise_px=" + format_double(o.noise_px) +
         " rate_hz=" + format_double(o.rate_hz) + " drift_ppm=" + format_double(o.drift_ppm) +
         " latency_ms=" + format_double(o.latency_ms) + " clock_offset_ms=" + format_double(o.clock_offset_ms) +
         " jitter_ms=" + format_double(o.jitter_ms) + " dropout=" + format_double(o.dropout) +
         " stray=" + format_double(o.stray) + " occlusion_per_s=" + format_double(o.occlusion_per_s) +
         " burst=" + format_double(o.burst);
}

}  // namespace

namespace detail {

Vec2 true_projection(const Camera& c, const Vec3& X) {
  const Vec3 xc = c.R * X + c.t;
  const double x = xc.x() / xc.z(), y = xc.y() / xc.z();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + c.K.k1 * r2 + c.K.k2 * r2 * r2;
  return {c.K.fx * radial * x + c.K.cx, c.K.fy * radial * y + c.K.cy};
}

void add_meta(std::vector<InputEvent>& ev, const std::string& key, const std::string& text) {
  InputEvent e;
  e.kind = EventKind::Meta;
  e.name = key;
  e.text = text;
  ev.push_back(std::move(e));
}

std::string numbers(std::initializer_list<double> v) {
  std::string s;
  for (double d : v) {
    if (!s.empty()) s += ' ';
    s += format_double(d);
  }
  return s;
}

// Runs both cameras over [0, duration) and writes the session: header facts, then every report
// in host arrival order, each followed by its truth, with `commands` (sorted by time) among them.
SimulatedSession run_session(const RigOptions& o, Scenario scenario, const SimulatedRig& rig, double duration_s, const Scene& scene,
                             const Occluded& occluded, std::vector<InputEvent> header, const std::vector<InputEvent>& commands) {
  SimulatedSession session;
  SimulationStats& stats = session.stats;
  stats.duration_s = duration_s;

  Random clock_rng(o.seed, stream_of(scenario, Stream::Clock));
  std::array<Clock, 2> clocks;
  for (int d = 0; d < 2; ++d) {
    const double rate = o.rate_hz * (1.0 + (d == 0 ? -0.5 : 0.5) * o.drift_ppm * 1e-6);
    clocks[d] = Clock{rate, clock_rng.uniform(0.0, 1.0 / rate),
                      (o.latency_ms + (d == 1 ? o.clock_offset_ms : 0.0)) * 1e-3, o.jitter_ms * 1e-3};
  }
  for (int d = 0; d < 2; ++d) {
    const Camera& c = rig.cameras[d];
    const Intrinsics& n = rig.nominal[d];
    add_meta(header, "nominal_intrinsics", std::to_string(d) + " " + numbers({n.fx, n.fy, n.cx, n.cy, n.k1, n.k2}));
    std::vector<double> v{static_cast<double>(d), c.K.fx, c.K.fy, c.K.cx, c.K.cy, c.K.k1, c.K.k2};
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) v.push_back(c.R(r, k));
    for (int k = 0; k < 3; ++k) v.push_back(c.t(k));
    add_truth(header, 0, "camera", std::move(v));
  }
  for (int d = 0; d < 2; ++d)
    add_truth(header, 0, "clock",
              {static_cast<double>(d), clocks[d].rate_hz, clocks[d].phase_s * 1e6, clocks[d].latency_s * 1e6,
               clocks[d].jitter_s * 1e6});

  // The stray reflection: a fixed spot in one camera's image, present in whole seconds.
  Random stray_rng(o.seed, stream_of(scenario, Stream::Stray));
  const Vec2 stray_px(stray_rng.uniform(100, 924), stray_rng.uniform(100, 668));
  std::vector<char> stray_on(static_cast<size_t>(std::ceil(duration_s)) + 1);
  for (char& on : stray_on) on = stray_rng.uniform() < o.stray;

  std::vector<PendingReport> reports;
  for (int d = 0; d < 2; ++d) {
    const Camera& cam = rig.cameras[d];
    const Vec3 centre = cam.centre();
    Random noise(o.seed, stream_of(scenario, d == 0 ? Stream::Noise0 : Stream::Noise1));
    Random timing(o.seed, stream_of(scenario, d == 0 ? Stream::Timing0 : Stream::Timing1));
    Random occlusion_rng(o.seed, stream_of(scenario, d == 0 ? Stream::Occlusion0 : Stream::Occlusion1));
    const std::vector<Interval> hand = occlusion_intervals(occlusion_rng, o.occlusion_per_s, duration_s);
    SlotTracker slots;
    const Clock& clock = clocks[d];
    for (int64_t k = 0;; ++k) {
      const double exposure = clock.phase_s + static_cast<double>(k) / clock.rate_hz;
      if (exposure >= duration_s) break;
      SceneSample sample = scene(exposure);
      std::vector<Blob> blobs;
      for (size_t i = 0; i < sample.lights.size(); ++i) {
        const Vec3& X = sample.lights[i];
        if ((cam.R * X + cam.t).z() <= 0) continue;
        ++stats.led_images;
        if (inside(hand, exposure) || (occluded && occluded(exposure, X, centre))) {
          ++stats.occluded;
          continue;
        }
        const Vec2 p = true_projection(cam, X) + o.noise_px * Vec2(noise.normal(), noise.normal());
        const double depth = (cam.R * X + cam.t).z();
        const auto size = static_cast<uint8_t>(std::clamp<long>(std::lround(3.2 / depth), 1, 15));
        blobs.push_back({p, size, static_cast<int>(i)});
      }
      if (d == kStrayDevice && stray_on[static_cast<size_t>(exposure)]) {
        ++stats.stray_frames;
        blobs.push_back({stray_px + o.noise_px * Vec2(noise.normal(), noise.normal()), 2, kStraySource});
      }
      // Blobs within one sensor pixel are one blob to the camera.
      for (size_t a = 0; a < blobs.size(); ++a)
        for (size_t b = a + 1; b < blobs.size();) {
          if ((blobs[a].px - blobs[b].px).norm() < kMergeDistancePx) {
            blobs[a].px = 0.5 * (blobs[a].px + blobs[b].px);
            blobs[a].size = static_cast<uint8_t>(std::min(15, blobs[a].size + blobs[b].size));
            blobs.erase(blobs.begin() + static_cast<std::ptrdiff_t>(b));
            ++stats.merged;
          } else {
            ++b;
          }
        }
      std::vector<Blob> visible;
      for (Blob b : blobs) {
        b.px = Vec2(std::round(b.px.x()), std::round(b.px.y()));
        if (b.px.x() < 0 || b.px.x() > kWiimoteWidth - 1 || b.px.y() < 0 || b.px.y() > kWiimoteHeight - 1) {
          if (b.source != kStraySource) ++stats.out_of_view;
          continue;
        }
        visible.push_back(b);
      }
      IrReport report;
      report.report_id = 0x33;
      report.accel = {0x82, 0x7F, 0x9B};  // at rest, lying flat
      report.slots = slots.assign(visible);
      // Lost reports still cost the draws above, so a dropout does not shift later noise.
      const double jitter = clock.jitter_s * timing.normal();
      if (timing.uniform() < o.dropout) {
        ++stats.dropped[d];
        continue;
      }
      const double arrival = exposure + std::max(0.0, clock.latency_s + jitter);
      reports.push_back({std::llround(arrival * 1e6), d, exposure, encode_ir_report(report), std::move(sample)});
      ++stats.reports[d];
    }
  }
  // Bluetooth delivers a remote's reports in order, so a late one holds back those behind it; and now and
  // then one is held until the next and both arrive at once. Reports are in exposure order per device.
  Random burst_rng(o.seed, stream_of(scenario, Stream::Burst));
  for (int d = 0; d < 2; ++d) {
    std::vector<PendingReport*> own;
    for (PendingReport& r : reports)
      if (r.device == d) own.push_back(&r);
    for (size_t k = 1; k < own.size(); ++k) own[k]->t_us = std::max(own[k]->t_us, own[k - 1]->t_us);
    for (size_t k = own.size(); k-- > 1;)
      if (burst_rng.uniform() < o.burst) own[k - 1]->t_us = own[k]->t_us;
  }
  std::stable_sort(reports.begin(), reports.end(), [](const PendingReport& a, const PendingReport& b) {
    return a.t_us != b.t_us ? a.t_us < b.t_us : a.device < b.device;
  });
  session.events = std::move(header);
  session.events.reserve(session.events.size() + 2 * reports.size());
  auto command = commands.begin();
  for (PendingReport& r : reports) {
    for (; command != commands.end() && command->t_us < r.t_us; ++command) session.events.push_back(*command);
    InputEvent hid;
    hid.t_us = r.t_us;
    hid.kind = EventKind::Hid;
    hid.device = r.device;
    hid.bytes = std::move(r.bytes);
    session.events.push_back(std::move(hid));
    std::vector<double> values{static_cast<double>(r.device), r.exposure_s * 1e6};
    values.insert(values.end(), r.scene.truth_values.begin(), r.scene.truth_values.end());
    add_truth(session.events, r.t_us, r.scene.truth_name, std::move(values));
  }
  session.events.insert(session.events.end(), command, commands.end());
  return session;
}

std::vector<InputEvent> common_header(const char* scenario, const RigOptions& o) {
  std::vector<InputEvent> h;
  add_meta(h, "scenario", scenario);
  add_meta(h, "seed", std::to_string(o.seed) + " rig_seed=" + std::to_string(o.rig_seed));
  add_meta(h, "rig", rig_options_text(o));
  return h;
}

}  // namespace detail

Result<SimulatedRig> make_simulated_rig(const RigOptions& o) {
  if (Status s = check_rig(o); !s) return Result<SimulatedRig>::failure(s.error);
  Random rng(o.rig_seed, static_cast<uint64_t>(Stream::Rig));
  SimulatedRig rig;
  const Vec3 target(0, 0, o.target_distance_m);
  for (int d = 0; d < 2; ++d) {
    Intrinsics K;
    K.fx = o.focal_px * (1.0 + rng.uniform(-0.01, 0.01));
    K.fy = K.fx * (1.0 + rng.uniform(-0.003, 0.003));
    K.cx = 512 + rng.uniform(-10, 10);
    K.cy = 384 + rng.uniform(-10, 10);
    K.k1 = o.k1 * (1.0 + rng.uniform(-0.2, 0.2));
    K.k2 = o.k2;
    const Vec3 centre((d == 0 ? -0.5 : 0.5) * o.baseline_m, rng.uniform(-0.01, 0.01), rng.uniform(-0.01, 0.01));
    const Vec3 aim = target + Vec3(rng.uniform(-0.03, 0.03), rng.uniform(-0.03, 0.03), rng.uniform(-0.03, 0.03));
    const Eigen::Matrix3d R = look_at(centre, aim, rng.uniform(-2, 2) * std::numbers::pi / 180.0);
    rig.cameras[d] = Camera{K, R, -R * centre};
    rig.nominal[d] = Intrinsics{.fx = K.fx * (1.0 + o.focal_error), .fy = K.fy * (1.0 + o.focal_error),
                                .cx = 512, .cy = 384, .k1 = 0, .k2 = 0};
  }
  return rig;
}

}  // namespace fire::simulation
