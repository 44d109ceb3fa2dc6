#include "tools/simulation/simulate.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <random>

#include "engine/ir_report.hpp"
#include "tools/simulation/drawing_plan.hpp"
#include "systems/tracking/registration.hpp"
#include "systems/tracking/rig_io.hpp"

namespace fire::simulation {
using namespace tracking;  // the cameras, calibration and tracking this simulation feeds and checks
namespace {

// Random numbers from raw 64-bit draws: the standard distributions differ between standard
// libraries, these do not. One stream per concern, so that turning one knob (say, dropouts)
// leaves the noise of every blob unchanged.
class Random {
 public:
  Random(uint64_t seed, uint64_t stream) : gen_(seed ^ (0x9E3779B97F4A7C15ull * (stream + 1))) {}
  double uniform() { return static_cast<double>(gen_() >> 11) * 0x1.0p-53; }
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }
  double exponential(double mean) { return -mean * std::log(1.0 - uniform()); }

 private:
  std::mt19937_64 gen_;
};

// Each scenario draws from its own streams, so a wand and a sketch session with the same seed
// share the rig (drawn from rig_seed) but no noise.
enum Scenario : uint64_t { kWandScenario = 1, kSketchScenario = 2, kDrawingScenario = 3 };
enum Stream : uint64_t { kRigStream, kClockStream, kStrayStream, kMotionStream, kNoiseStream0, kNoiseStream1,
                         kTimingStream0, kTimingStream1, kOcclusionStream0, kOcclusionStream1, kBurstStream };
uint64_t stream_of(Scenario scenario, Stream s) { return 64 * scenario + s; }

constexpr double kMergeDistancePx = 8.0;  // one pixel of the 128 x 96 sensor
constexpr int kStrayDevice = 1;
constexpr int kStraySource = 100;
constexpr double kLedRadius = 0.0015;  // the LED's centre sits this far off the surface it touches

// The same pinhole-plus-radial model as Camera::project, written out here so that the simulator
// does not test the calibration with the calibration's own code.
Vec2 true_projection(const Camera& c, const Vec3& X) {
  const Vec3 xc = c.R * X + c.t;
  const double x = xc.x() / xc.z(), y = xc.y() / xc.z();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + c.K.k1 * r2 + c.K.k2 * r2 * r2;
  return {c.K.fx * radial * x + c.K.cx, c.K.fy * radial * y + c.K.cy};
}

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

// Ray-triangle intersection (Moller-Trumbore); the distance along `dir` or nothing.
std::optional<double> intersect(const Vec3& origin, const Vec3& dir, const std::array<Vec3, 3>& tri) {
  const Vec3 e1 = tri[1] - tri[0], e2 = tri[2] - tri[0];
  const Vec3 p = dir.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-18) return std::nullopt;
  const double inv = 1.0 / det;
  const Vec3 s = origin - tri[0];
  const double u = s.dot(p) * inv;
  if (u < 0 || u > 1) return std::nullopt;
  const Vec3 q = s.cross(e1);
  const double v = dir.dot(q) * inv;
  if (v < 0 || u + v > 1) return std::nullopt;
  return e2.dot(q) * inv;
}

using Triangles = std::vector<std::array<Vec3, 3>>;

// Whether one of triangles [first, last) crosses the segment from + s dir, s in (0, len).
bool crossed(const Triangles& tris, size_t first, size_t last, const Vec3& from, const Vec3& dir, double len) {
  for (size_t k = first; k < last; ++k) {
    const auto t = intersect(from, dir, tris[k]);
    if (t && *t > 0 && *t < len) return true;
  }
  return false;
}

bool segment_blocked(const Triangles& tris, const Vec3& from, const Vec3& to) {
  const Vec3 d = to - from;
  const double len = d.norm();
  return crossed(tris, 0, tris.size(), from, d / len, len);
}

// What one camera exposes at one instant: lit LEDs in the world, and the truth line to log.
struct SceneSample {
  std::vector<Vec3> lights;
  std::string truth_name;
  std::vector<double> truth_values;  // after device and exposure instant
};
using Scene = std::function<SceneSample(double t_s)>;

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

void add_meta(std::vector<InputEvent>& ev, const std::string& key, const std::string& text) {
  InputEvent e;
  e.kind = EventKind::Meta;
  e.name = key;
  e.text = text;
  ev.push_back(std::move(e));
}

void add_truth(std::vector<InputEvent>& ev, int64_t t_us, const std::string& name, std::vector<double> values) {
  InputEvent e;
  e.t_us = t_us;
  e.kind = EventKind::Truth;
  e.name = name;
  e.values = std::move(values);
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

// Whether the object (or nothing, when empty) hides a light from a camera's centre at time t.
using Occluded = std::function<bool(double t_s, const Vec3& light, const Vec3& camera_centre)>;

// Runs both cameras over [0, duration) and writes the session: header facts, then every report
// in host arrival order, each followed by its truth, with `commands` (sorted by time) among them.
SimulatedSession run_session(const RigOptions& o, Scenario scenario, const SimulatedRig& rig, double duration_s, const Scene& scene,
                             const Occluded& occluded, std::vector<InputEvent> header, const std::vector<InputEvent>& commands = {}) {
  SimulatedSession session;
  SimulationStats& stats = session.stats;
  stats.duration_s = duration_s;

  Random clock_rng(o.seed, stream_of(scenario, kClockStream));
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
  Random stray_rng(o.seed, stream_of(scenario, kStrayStream));
  const Vec2 stray_px(stray_rng.uniform(100, 924), stray_rng.uniform(100, 668));
  std::vector<char> stray_on(static_cast<size_t>(std::ceil(duration_s)) + 1);
  for (char& on : stray_on) on = stray_rng.uniform() < o.stray;

  std::vector<PendingReport> reports;
  for (int d = 0; d < 2; ++d) {
    const Camera& cam = rig.cameras[d];
    const Vec3 centre = cam.centre();
    Random noise(o.seed, stream_of(scenario, d == 0 ? kNoiseStream0 : kNoiseStream1));
    Random timing(o.seed, stream_of(scenario, d == 0 ? kTimingStream0 : kTimingStream1));
    Random occlusion_rng(o.seed, stream_of(scenario, d == 0 ? kOcclusionStream0 : kOcclusionStream1));
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
  Random burst_rng(o.seed, stream_of(scenario, kBurstStream));
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

// Catmull-Rom through evenly timed keys; `keys` needs one extra key before and two after.
template <class V>
V catmull_rom(const std::vector<V>& keys, double u) {
  const auto i = static_cast<size_t>(u);
  const double s = u - static_cast<double>(i);
  const V& p0 = keys[i];
  const V& p1 = keys[i + 1];
  const V& p2 = keys[i + 2];
  const V& p3 = keys[i + 3];
  const double s2 = s * s, s3 = s2 * s;
  return 0.5 * ((2.0 * p1) + (-p0 + p2) * s + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * s2 + (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * s3);
}

// --- the sketch: strokes on the object's surface ---

struct PlacedMesh {
  Triangles triangles;
  double height = 0;
  Vec3 base_centre = Vec3::Zero();  // on the object's axis at its lowest point
};

Result<PlacedMesh> place_mesh(const PolygonMeshView& mesh, double height_m, double distance_m) {
  using R = Result<PlacedMesh>;
  if (mesh.positions.empty() || mesh.face_offsets.size() < 2) return R::failure("the mesh has no faces");
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : mesh.positions) {
    if (!p.allFinite()) return R::failure("the mesh has a non-finite vertex");
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double extent = hi.z() - lo.z();
  if (!(extent > 0)) return R::failure("the mesh is flat along z (its up axis)");
  if (!(height_m > 0) || !std::isfinite(height_m)) return R::failure("the object height must be positive");
  const double scale = height_m / extent;
  // Model (x, y, z) with z up -> world (x, -z, y): a rotation about x, up becomes -y.
  const Vec3 axis(0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), lo.z());
  PlacedMesh out;
  out.height = height_m;
  out.base_centre = Vec3(0, 0.5 * height_m, distance_m);
  auto place = [&](const Vec3& p) -> Vec3 {
    const Vec3 q = (p - axis) * scale;
    return Vec3(q.x(), -q.z(), q.y()) + out.base_centre;
  };
  for (size_t f = 0; f + 1 < mesh.face_offsets.size(); ++f) {
    const uint32_t first = mesh.face_offsets[f], last = mesh.face_offsets[f + 1];
    if (last < first + 3 || last > mesh.face_vertices.size()) return R::failure("face " + std::to_string(f) + " is malformed");
    for (uint32_t k = first; k < last; ++k)
      if (mesh.face_vertices[k] >= mesh.positions.size())
        return R::failure("face " + std::to_string(f) + " uses a vertex out of range");
    const Vec3 a = place(mesh.positions[mesh.face_vertices[first]]);
    for (uint32_t k = first + 1; k + 1 < last; ++k)
      out.triangles.push_back({a, place(mesh.positions[mesh.face_vertices[k]]), place(mesh.positions[mesh.face_vertices[k + 1]])});
  }
  return out;
}

// A stroke drawn from (theta0, h0) to (theta1, h1): azimuth about the object's axis (0 faces the
// cameras) and height as a fraction of the object's.
struct StrokePlan {
  double theta0_deg, h0, theta1_deg, h1;
};

constexpr StrokePlan kStrokePlans[] = {
    {0, 0.05, 0, 0.9},     {-55, 0.25, 55, 0.25},  {-30, 0.05, -30, 0.9}, {-55, 0.45, 55, 0.45},
    {-50, 0.1, 40, 0.85},  {30, 0.05, 30, 0.9},    {-55, 0.08, 55, 0.08}, {-50, 0.05, -50, 0.9},
    {-55, 0.62, 55, 0.62}, {50, 0.15, -40, 0.7},   {50, 0.05, 50, 0.9},   {-50, 0.8, 50, 0.8},
};

// Samples the surface along the plan by casting horizontal rays outward from the axis; the
// outermost hit is the surface. The radius is smoothed over a few millimetres, as a pen tip
// glides over the facets of a polygonal model, and the LED sits kLedRadius outside.
std::vector<Vec3> stroke_path(const PlacedMesh& m, const StrokePlan& plan) {
  constexpr int kSamples = 800;
  std::vector<double> radius, theta, height;
  for (int i = 0; i <= kSamples; ++i) {
    const double u = static_cast<double>(i) / kSamples;
    const double th = (plan.theta0_deg + u * (plan.theta1_deg - plan.theta0_deg)) * std::numbers::pi / 180.0;
    const double h = (plan.h0 + u * (plan.h1 - plan.h0)) * m.height;
    const Vec3 origin = m.base_centre - Vec3(0, h, 0);
    const Vec3 dir(std::sin(th), 0, -std::cos(th));
    double best = -1;
    for (const auto& tri : m.triangles)
      if (const auto t = intersect(origin, dir, tri); t && *t > best) best = *t;
    if (best <= 0) break;  // the ray left the object: the stroke ends here
    radius.push_back(best);
    theta.push_back(th);
    height.push_back(h);
  }
  std::vector<Vec3> path;
  const int n = static_cast<int>(radius.size());
  if (n < 2) return path;
  constexpr int kHalfWindow = 15;
  constexpr double kSigma = 5.0;
  for (int i = 0; i < n; ++i) {
    double sum = 0, weight = 0;
    for (int k = std::max(0, i - kHalfWindow); k <= std::min(n - 1, i + kHalfWindow); ++k) {
      const double w = std::exp(-0.5 * (k - i) * (k - i) / (kSigma * kSigma));
      sum += w * radius[static_cast<size_t>(k)];
      weight += w;
    }
    const double r = sum / weight + kLedRadius;
    const auto s = static_cast<size_t>(i);
    path.push_back(m.base_centre - Vec3(0, height[s], 0) + r * Vec3(std::sin(theta[s]), 0, -std::cos(theta[s])));
  }
  return path;
}

struct Polyline {
  std::vector<Vec3> points;
  std::vector<double> arc;  // cumulative length
  Vec3 at(double s) const {
    if (s <= 0) return points.front();
    if (s >= arc.back()) return points.back();
    const size_t i = static_cast<size_t>(std::upper_bound(arc.begin(), arc.end(), s) - arc.begin()) - 1;
    const double len = arc[i + 1] - arc[i];
    return len > 0 ? Vec3(points[i] + (s - arc[i]) / len * (points[i + 1] - points[i])) : points[i];
  }
};

Polyline make_polyline(std::vector<Vec3> points) {
  Polyline p;
  p.arc.push_back(0);
  for (size_t i = 1; i < points.size(); ++i) p.arc.push_back(p.arc.back() + (points[i] - points[i - 1]).norm());
  p.points = std::move(points);
  return p;
}

// Constant acceleration up to the cruise speed and down again (a triangle on short strokes).
struct SpeedProfile {
  double length, cruise, accel;
  double ramp_time() const { return std::min(cruise / accel, std::sqrt(length / accel)); }
  double duration() const {
    const double tr = ramp_time();
    const double peak = accel * tr;
    return 2 * tr + (length - peak * tr) / peak;
  }
  // Distance travelled and speed at time t into the move.
  std::pair<double, double> at(double t) const {
    const double tr = ramp_time(), peak = accel * tr, total = duration();
    if (t <= 0) return {0, 0};
    if (t >= total) return {length, 0};
    if (t < tr) return {0.5 * accel * t * t, accel * t};
    if (t > total - tr) {
      const double r = total - t;
      return {length - 0.5 * accel * r * r, accel * r};
    }
    return {0.5 * peak * tr + peak * (t - tr), peak};
  }
};

enum class Phase { Travel, Hold, Move };
struct Segment {
  Phase phase;
  double begin, end;
  int stroke;      // index into the strokes drawn
  Vec3 from, to;   // Travel: straight line, Hold: `from`
};

// How the pen moves along a stroke: its cruising speed and its acceleration at both ends.
struct PenMotion {
  double speed_m_s, accel_m_s2;
};

// The pen at `time` of a timeline of strokes: where it is, whether its LED is lit, its truth record.
SceneSample pen_at(const std::vector<Segment>& timeline, const std::vector<Polyline>& strokes, PenMotion motion,
                   double time) {
  const auto it = std::upper_bound(timeline.begin(), timeline.end(), time,
                                   [](double v, const Segment& s) { return v < s.begin; });
  const Segment& seg = *(it == timeline.begin() ? it : it - 1);
  Vec3 p = seg.from;
  bool lit = false;
  double speed = 0, still = 0;
  switch (seg.phase) {
    case Phase::Travel: {
      const double len = seg.end - seg.begin;
      const double u = std::isfinite(len) && len > 0 ? std::clamp((time - seg.begin) / len, 0.0, 1.0) : 0.0;
      p = seg.from + u * (seg.to - seg.from);
      break;
    }
    case Phase::Hold:
      lit = true;
      still = time - seg.begin;
      break;
    case Phase::Move: {
      const Polyline& path = strokes[static_cast<size_t>(seg.stroke)];
      const auto [s, v] = SpeedProfile{path.arc.back(), motion.speed_m_s, motion.accel_m_s2}.at(time - seg.begin);
      p = path.at(s);
      lit = true;
      speed = v;
      break;
    }
  }
  SceneSample out{{}, "pen", {p.x(), p.y(), p.z(), lit ? 1.0 : 0.0, speed, still}};
  if (lit) out.lights.push_back(p);
  return out;
}

}  // namespace

Result<SimulatedRig> make_simulated_rig(const RigOptions& o) {
  if (Status s = check_rig(o); !s) return Result<SimulatedRig>::failure(s.error);
  Random rng(o.rig_seed, kRigStream);
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

Result<std::string> true_rig_json(const RigOptions& o) {
  Result<SimulatedRig> rig = make_simulated_rig(o);
  if (!rig) return Result<std::string>::failure(rig.error());
  CalibrationResult calibrated;
  calibrated.cam0 = rig->cameras[0];
  calibrated.cam1 = rig->cameras[1];
  calibrated.time_offset_us = o.clock_offset_ms * 1e3;
  return rig_to_json(calibrated);
}

Result<SimulatedSession> simulate_wand(const RigOptions& o, const WandOptions& w) {
  using R = Result<SimulatedSession>;
  Result<SimulatedRig> rig = make_simulated_rig(o);
  if (!rig) return R::failure(rig.error());
  if (!(w.duration_s > 0 && w.duration_s <= 3600)) return R::failure("wand duration must be within (0, 3600] s");
  if (!(w.length_m > 0.01 && w.length_m < 2)) return R::failure("wand length must be within (0.01, 2) m");

  // The wand's centre and direction pass through random keys every half second: centres in a
  // box in front of the rig, directions kept away from the line of sight (where its two LEDs
  // would merge) and turning less than 90 degrees per key, as a hand waves.
  constexpr double kKeyInterval = 0.5;
  Random motion(o.seed, stream_of(kWandScenario, kMotionStream));
  const size_t keys = static_cast<size_t>(w.duration_s / kKeyInterval) + 4;
  std::vector<Vec3> centres, directions;
  for (size_t i = 0; i < keys; ++i) {
    centres.emplace_back(motion.uniform(-0.2, 0.2), motion.uniform(-0.15, 0.15),
                         o.target_distance_m + motion.uniform(-0.2, 0.2));
    Vec3 d;
    do {
      d = Vec3(motion.normal(), motion.normal(), motion.normal());
    } while (d.norm() < 1e-3 || std::abs(d.normalized().z()) > 0.75);
    d.normalize();
    if (!directions.empty() && d.dot(directions.back()) < 0) d = -d;
    directions.push_back(d);
  }
  const double half = 0.5 * w.length_m;
  Scene scene = [&](double t) {
    const double u = t / kKeyInterval;
    const Vec3 c = catmull_rom(centres, u);
    const Vec3 d = catmull_rom(directions, u).normalized();
    const Vec3 a = c + half * d, b = c - half * d;
    return SceneSample{{a, b}, "wand", {a.x(), a.y(), a.z(), b.x(), b.y(), b.z()}};
  };
  std::vector<InputEvent> header = common_header("wand", o);
  add_meta(header, "wand_length_m", format_double(w.length_m));
  return run_session(o, kWandScenario, *rig, w.duration_s, scene, {}, std::move(header));
}

Result<SimulatedSession> simulate_sketch(const RigOptions& o, const SketchOptions& sk, const PolygonMeshView& mesh) {
  using R = Result<SimulatedSession>;
  Result<SimulatedRig> rig = make_simulated_rig(o);
  if (!rig) return R::failure(rig.error());
  if (!(sk.duration_s > 0 && sk.duration_s <= 3600)) return R::failure("sketch duration must be within (0, 3600] s");
  if (sk.strokes < 1 || sk.strokes > 1000) return R::failure("strokes must be within 1..1000");
  if (!(sk.speed_m_s > 0.01 && sk.speed_m_s <= 5)) return R::failure("pen speed must be within (0.01, 5] m/s");
  if (!(sk.hold_s >= 0 && sk.hold_s <= 60)) return R::failure("hold must be within [0, 60] s");
  Result<PlacedMesh> placed = place_mesh(mesh, sk.height_m, o.target_distance_m);
  if (!placed) return R::failure(placed.error());

  constexpr double kAccel = 5.0;      // m/s^2, a brisk but human start and stop
  constexpr double kTravel_s = 0.6;   // unlit move from one stroke to the next
  constexpr double kLeadIn_s = 0.5;   // unlit before the first stroke
  std::vector<Polyline> strokes;
  std::vector<Segment> timeline;
  double t = kLeadIn_s;
  const size_t plan_count = std::size(kStrokePlans);
  for (int i = 0; i < sk.strokes && t < sk.duration_s; ++i) {
    StrokePlan plan = kStrokePlans[static_cast<size_t>(i) % plan_count];
    // Later rounds of the plan list turn by a few degrees, so that no stroke repeats.
    const double turn = 7.0 * static_cast<double>(static_cast<size_t>(i) / plan_count);
    plan.theta0_deg += turn;
    plan.theta1_deg += turn;
    Polyline path = make_polyline(stroke_path(*placed, plan));
    if (path.points.size() < 2) continue;
    const int id = static_cast<int>(strokes.size());
    const Vec3 start = path.points.front(), end = path.points.back();
    const Vec3 prev = timeline.empty() ? start : timeline.back().from;
    if (timeline.empty()) {
      timeline.push_back({Phase::Travel, 0, t, id, start, start});
    } else {
      timeline.push_back({Phase::Travel, t, t + kTravel_s, id, prev, start});
      t += kTravel_s;
    }
    const double move = SpeedProfile{path.arc.back(), sk.speed_m_s, kAccel}.duration();
    timeline.push_back({Phase::Hold, t, t + sk.hold_s, id, start, start});
    t += sk.hold_s;
    timeline.push_back({Phase::Move, t, t + move, id, start, end});
    t += move;
    timeline.push_back({Phase::Hold, t, t + sk.hold_s, id, end, end});
    t += sk.hold_s;
    strokes.push_back(std::move(path));
  }
  if (strokes.empty()) return R::failure("no stroke could be placed on the mesh (does its +z axis point up?)");
  const double duration = std::min(sk.duration_s, t + 0.3);
  timeline.push_back({Phase::Travel, t, std::numeric_limits<double>::infinity(), -1, timeline.back().from,
                      timeline.back().from});

  Scene scene = [&](double time) { return pen_at(timeline, strokes, PenMotion{sk.speed_m_s, kAccel}, time); };
  std::vector<InputEvent> header = common_header("sketch", o);
  add_meta(header, "mesh", sk.mesh_name + " height_m=" + format_double(sk.height_m));
  add_meta(header, "sketch", "strokes=" + std::to_string(strokes.size()) + " speed_m_s=" + format_double(sk.speed_m_s) +
                                 " hold_s=" + format_double(sk.hold_s));
  const Occluded occluded = [&](double, const Vec3& light, const Vec3& centre) {
    return segment_blocked(placed->triangles, light, centre);
  };
  Result<SimulatedSession> session = run_session(o, kSketchScenario, *rig, duration, scene, occluded, std::move(header));
  if (session) session->stats.strokes = static_cast<int>(strokes.size());
  return session;
}

Result<std::vector<Vec3>> object_frame(std::span<const Vec3> positions, double height_m) {
  using R = Result<std::vector<Vec3>>;
  if (positions.empty()) return R::failure("the mesh has no vertices");
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : positions) {
    if (!p.allFinite()) return R::failure("the mesh has a non-finite vertex");
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if (!(hi.z() > lo.z())) return R::failure("the mesh is flat along z (its up axis)");
  if (!(height_m > 0) || !std::isfinite(height_m)) return R::failure("the object height must be positive");
  const double scale = height_m / (hi.z() - lo.z());
  const Vec3 base(0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), lo.z());
  std::vector<Vec3> out;
  out.reserve(positions.size());
  for (const Vec3& p : positions) out.push_back((p - base) * scale);
  return out;
}

namespace {

// One way the object stands before the rig: world = R * object + t.
struct Pose {
  Eigen::Matrix3d R;
  Vec3 t;
  Triangles triangles;  // the object's surface, placed
  // Bounds of each run of kTrianglesPerBox triangles: a segment that misses them misses every one.
  std::vector<std::pair<Vec3, Vec3>> boxes;
  Vec3 operator()(const Vec3& object) const { return R * object + t; }
  void place(const Triangles& object);
};

constexpr size_t kTrianglesPerBox = 32;

void Pose::place(const Triangles& object) {
  for (const auto& tri : object) triangles.push_back({(*this)(tri[0]), (*this)(tri[1]), (*this)(tri[2])});
  constexpr double kPad = 1e-6;  // metres: keeps the test conservative against rounding
  for (size_t first = 0; first < triangles.size(); first += kTrianglesPerBox) {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (size_t k = first; k < std::min(triangles.size(), first + kTrianglesPerBox); ++k)
      for (const Vec3& p : triangles[k]) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    boxes.push_back({lo - Vec3::Constant(kPad), hi + Vec3::Constant(kPad)});
  }
}

// Whether the segment from + s dir, s in [0, len], meets the box (slab test).
bool segment_meets_box(const Vec3& from, const Vec3& dir, double len, const std::pair<Vec3, Vec3>& box) {
  double near = 0, far = len;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(dir[a]) < 1e-12) {
      if (from[a] < box.first[a] || from[a] > box.second[a]) return false;
      continue;
    }
    double t0 = (box.first[a] - from[a]) / dir[a], t1 = (box.second[a] - from[a]) / dir[a];
    if (t0 > t1) std::swap(t0, t1);
    near = std::max(near, t0);
    far = std::min(far, t1);
    if (near > far) return false;
  }
  return true;
}

// A light on the limit surface lies within a millimetre of the object's faces (its limit surface, finely), on
// either side: the object hides it only beyond this distance toward the camera.
constexpr double kSurfaceClearance = 0.006;
constexpr double kImageMargin = 16;  // pixels: a blob this close to the image's edge may leave it
constexpr double kMarkSpacing = 0.02;  // metres between marks the person adds: registration needs them apart
// How much further than --tilt the object leans where that tilt shows too little (into a vessel, under a base).
constexpr std::array<double, 4> kFurtherTilt_deg{0, 35, 60, 80};

bool hidden(const Pose& pose, const Vec3& light, const Vec3& centre) {
  const Vec3 u = (centre - light).normalized();
  const Vec3 from = light + kSurfaceClearance * u;
  const double len = (centre - from).norm();
  const Vec3 dir = (centre - from) / len;
  for (size_t b = 0; b < pose.boxes.size(); ++b)
    if (segment_meets_box(from, dir, len, pose.boxes[b]) &&
        crossed(pose.triangles, b * kTrianglesPerBox, std::min(pose.triangles.size(), (b + 1) * kTrianglesPerBox), from, dir, len))
      return true;
  return false;
}

bool seen_by_both(const SimulatedRig& rig, const Pose& pose, const Vec3& object_point) {
  const Vec3 X = pose(object_point);
  for (const Camera& c : rig.cameras) {
    if ((c.R * X + c.t).z() <= 0) return false;
    const Vec2 px = true_projection(c, X);
    if (px.x() < kImageMargin || px.x() > kWiimoteWidth - 1 - kImageMargin || px.y() < kImageMargin ||
        px.y() > kWiimoteHeight - 1 - kImageMargin)
      return false;
    if (hidden(pose, X, c.centre())) return false;
  }
  return true;
}

// What the person does, in order.
struct Step {
  enum Kind { Register, Stroke, Undo, Hole } kind;
  int pose = 0;
  std::vector<Vec3> points;  // Stroke: object frame; Hole: the point touched
};

Status check_drawing(const DrawingOptions& d, const PolygonMeshView& object, const DrawingNetwork& net) {
  const std::pair<const char*, double> named[] = {{"speed", d.speed_m_s}, {"hold", d.hold_s}, {"mark hold", d.mark_hold_s},
                                                   {"tilt", d.tilt_deg}, {"height", d.height_m}};
  for (const auto& [name, value] : named)
    if (!std::isfinite(value)) return Status::failure(std::string("the ") + name + " must be a finite number");
  if (!(d.speed_m_s > 0.01 && d.speed_m_s <= 5)) return Status::failure("pen speed must be within (0.01, 5] m/s");
  if (!(d.hold_s >= 0 && d.hold_s <= 10)) return Status::failure("hold must be within [0, 10] s");
  if (!(d.mark_hold_s >= 0.8 && d.mark_hold_s <= 10))
    return Status::failure("mark hold must be within [0.8, 10] s (registration averages the pen's last 0.5 s on a mark)");
  if (!(std::abs(d.tilt_deg) <= 60)) return Status::failure("tilt must be within [-60, 60] degrees");
  if (d.turns < 1 || d.turns > 36) return Status::failure("turns must be within 1..36");
  if (d.undo_after < 0 || d.max_strokes < 0) return Status::failure("undo-after and max-strokes must not be negative");
  if (object.positions.empty() || object.face_offsets.size() < 2) return Status::failure("the object has no faces");
  if (net.curves.empty()) return Status::failure("the network has no curves");
  for (size_t k = 0; k < net.curves.size(); ++k) {
    const DrawingCurve& c = net.curves[k];
    if (c.a >= net.vertices.size() || c.b >= net.vertices.size() || c.a == c.b || c.points.size() < 2)
      return Status::failure("network curve " + std::to_string(k) + " is malformed (vertices out of range, a loop or fewer than 2 points)");
    for (const Vec3& p : c.points)
      if (!p.allFinite()) return Status::failure("network curve " + std::to_string(k) + " has a non-finite point");
  }
  return Status::success();
}

}  // namespace

Result<SimulatedDrawing> simulate_drawing(const RigOptions& o, const DrawingOptions& d, const PolygonMeshView& object,
                                          const DrawingNetwork& net) {
  using R = Result<SimulatedDrawing>;
  Result<SimulatedRig> rig = make_simulated_rig(o);
  if (!rig) return R::failure(rig.error());
  if (Status s = check_drawing(d, object, net); !s) return R::failure(s.error);

  // The object's control mesh as triangles, and its poses: standing (+z up is the world's -y), turned by
  // 360/turns degrees about its up axis, leaning its top toward the cameras, its middle where they converge.
  Triangles triangles;
  double top = 0;
  for (const Vec3& p : object.positions) top = std::max(top, p.z());
  for (size_t f = 0; f + 1 < object.face_offsets.size(); ++f) {
    const uint32_t first = object.face_offsets[f], last = object.face_offsets[f + 1];
    if (last < first + 3 || last > object.face_vertices.size()) return R::failure("face " + std::to_string(f) + " is malformed");
    for (uint32_t k = first; k < last; ++k)
      if (object.face_vertices[k] >= object.positions.size()) return R::failure("face " + std::to_string(f) + " uses a vertex out of range");
    for (uint32_t k = first + 1; k + 1 < last; ++k)
      triangles.push_back({object.positions[object.face_vertices[first]], object.positions[object.face_vertices[k]],
                           object.positions[object.face_vertices[k + 1]]});
  }
  // The poses: standing, turned by 360/turns degrees about its up axis, leaning its top toward the cameras,
  // its middle where they converge; and, where the object needs it (a closed one always), the same upside down
  // (poses turns..2 turns-1), turned over about its x axis.
  std::vector<Pose> poses;
  std::vector<Vec3> marks;
  std::vector<std::vector<uint32_t>> marks_seen;
  std::vector<std::vector<char>> shows;
  std::vector<std::vector<std::vector<char>>> seen;
  const bool closed = network_closed(net);
  auto attempt = [&](int sides, int tilts) -> Result<DrawingPlan> {
    Eigen::Matrix3d standing;
    standing << 1, 0, 0, 0, 0, -1, 0, 1, 0;
    const Eigen::Matrix3d over = Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitX()).toRotationMatrix();
    poses.clear();
    for (int side = 0; side < sides; ++side)
      for (int tilt = 0; tilt < tilts; ++tilt) {
        const double lean_deg = d.tilt_deg + kFurtherTilt_deg[static_cast<size_t>(tilt)];
        const Eigen::Matrix3d lean = Eigen::AngleAxisd(lean_deg * std::numbers::pi / 180, Vec3::UnitX()).toRotationMatrix();
        for (int j = 0; j < d.turns; ++j) {
          const double turn = 2 * std::numbers::pi * j / d.turns;
          Pose pose;
          pose.R = lean * standing * (side ? over : Eigen::Matrix3d::Identity()) * Eigen::AngleAxisd(-turn, Vec3::UnitZ()).toRotationMatrix();
          pose.t = Vec3(0, 0, o.target_distance_m) - pose.R * Vec3(0, 0, 0.5 * top);
          pose.place(triangles);
          poses.push_back(std::move(pose));
        }
      }

    // Six marks among the network's vertices: around the object every 60 degrees, at a fifth and at half its
    // height; on a closed object at a third and two thirds, where it is seen both ways up and rests on neither.
    constexpr int kMarks = 6;
    const double low = closed ? 1.0 / 3 : 0.2, high = closed ? 2.0 / 3 : 0.5;
    marks.clear();
    for (int k = 0; k < kMarks; ++k) {
      const double azimuth = 2 * k * std::numbers::pi / kMarks, height = (k % 2 ? high : low) * top;
      double best = std::numeric_limits<double>::infinity();
      const Vec3* pick = &net.vertices.front();
      for (const Vec3& p : net.vertices) {
        if (std::find(marks.begin(), marks.end(), p) != marks.end() || std::hypot(p.x(), p.y()) < 1e-6) continue;
        double off = std::abs(std::remainder(std::atan2(p.x(), -p.y()) - azimuth, 2 * std::numbers::pi));
        off += 3 * std::abs(p.z() - height) / top;
        if (off < best) best = off, pick = &p;
      }
      marks.push_back(*pick);
    }
    // A pose that sees fewer than 3 of them gets more, on its curves where both cameras see them and away from
    // where the object rests in it (its base, or its top upside down), each as far as can be from the marks it
    // sees already.
    auto marks_in = [&](size_t pose) {
      std::vector<uint32_t> out;
      for (uint32_t m = 0; m < marks.size(); ++m)
        if (seen_by_both(*rig, poses[pose], marks[m])) out.push_back(m);
      return out;
    };
    for (size_t j = 0; j < poses.size(); ++j) {
      const bool upside_down = sides == 2 && j >= poses.size() / 2;
      for (std::vector<uint32_t> now = marks_in(j); now.size() < 3; now = marks_in(j)) {
        double best = kMarkSpacing;
        std::optional<Vec3> pick;
        for (const DrawingCurve& c : net.curves)
          for (const Vec3& p : c.points) {
            if (upside_down ? p.z() > 0.9 * top : p.z() < 0.1 * top) continue;
            double spread = std::numeric_limits<double>::infinity();
            for (const Vec3& m : marks) spread = std::min(spread, (p - m).norm());
            if (spread > best && seen_by_both(*rig, poses[j], p)) best = spread, pick = p;
          }
        if (!pick) break;
        marks.push_back(*pick);
      }
    }
    marks_seen.assign(poses.size(), {});
    for (size_t j = 0; j < poses.size(); ++j) marks_seen[j] = marks_in(j);

    // Which points of each curve both cameras see in each pose (on a pose with at least 3 marks to register on).
    seen.assign(poses.size(), std::vector<std::vector<char>>(net.curves.size()));
    shows.assign(poses.size(), std::vector<char>(net.curves.size(), 0));
    for (size_t j = 0; j < poses.size(); ++j)
      for (size_t k = 0; k < net.curves.size(); ++k) {
        seen[j][k].assign(net.curves[k].points.size(), 0);
        if (marks_seen[j].size() >= 3)
          for (size_t i = 0; i < net.curves[k].points.size(); ++i) seen[j][k][i] = seen_by_both(*rig, poses[j], net.curves[k].points[i]);
        shows[j][k] = std::all_of(seen[j][k].begin(), seen[j][k].end(), [](char c) { return c != 0; });
      }
    PoseQuestions questions;
    // Poses nearest the current one first: the same way up and lean, then the other lean, then turned over.
    questions.order = [&](int current) {
      const int side = current / (tilts * d.turns), tilt = current / d.turns % tilts, turn = current % d.turns;
      std::vector<int> order;
      for (int s : {side, 1 - side}) {
        if (s >= sides) continue;
        std::vector<int> by_lean(static_cast<size_t>(tilts));
        std::iota(by_lean.begin(), by_lean.end(), 0);
        std::stable_sort(by_lean.begin(), by_lean.end(), [&](int x, int y) { return std::abs(x - tilt) < std::abs(y - tilt); });
        for (int t : by_lean) {
          const int base = (s * tilts + t) * d.turns;
          order.push_back(base + turn);
          for (int step = 1; step <= d.turns / 2; ++step)
            for (int j : {(turn + step) % d.turns, (turn - step + d.turns) % d.turns})
              if (std::find(order.begin(), order.end(), base + j) == order.end()) order.push_back(base + j);
        }
      }
      return order;
    };
    questions.sees = [&](int pose, uint32_t curve, size_t point) { return seen[static_cast<size_t>(pose)][curve][point] != 0; };
    return plan_drawing(net, questions, d.max_strokes, d.undo_after);
  };
  // Upside down, and leaning further, only where the object needs it.
  Result<DrawingPlan> planned = attempt(closed ? 2 : 1, 1);
  if (!planned && !closed) planned = attempt(2, 1);
  if (!planned) planned = attempt(2, static_cast<int>(kFurtherTilt_deg.size()));
  if (!planned) return R::failure(planned.error());
  std::vector<Step> plan;
  for (const PlanStep& s : planned->steps) plan.push_back({static_cast<Step::Kind>(s.kind), s.pose, s.points});

  // The timeline: where the pen is, lit or not, and when each command is logged.
  constexpr double kAccel = 2.0;     // m/s^2, a hand drawing with care
  constexpr double kTravel_s = 0.6;  // the pen lifted from one stroke or mark to the next: longer than a gap a stroke survives
  constexpr double kTurn_s = 3.0;    // turning the object, the pen lifted
  constexpr double kUndoWait_s = 1.0;  // after a stroke, before its undo: its pen up has reached the sketch
  std::vector<Polyline> strokes;
  std::vector<Segment> timeline;
  std::vector<InputEvent> commands;
  std::vector<std::pair<double, int>> pose_from{{0.0, plan.front().pose}};
  DrawingStats stats;
  stats.curves_total = net.curves.size();
  stats.curves_drawn = planned->curves_drawn;
  double t = 0.5;
  Vec3 pen = poses[static_cast<size_t>(plan.front().pose)].t;
  auto command = [&](double at, CommandKind kind, uint32_t mark = 0, const Vec3& p = Vec3::Zero()) {
    InputEvent e;
    e.t_us = std::llround(at * 1e6);
    e.kind = EventKind::Command;
    e.command = kind;
    e.mark = mark;
    e.p = p;
    commands.push_back(std::move(e));
  };
  auto travel_to = [&](const Vec3& to, double seconds) {
    timeline.push_back({Phase::Travel, t, t + seconds, -1, pen, to});
    t += seconds;
    pen = to;
  };
  auto hold = [&](double seconds) {
    timeline.push_back({Phase::Hold, t, t + seconds, -1, pen, pen});
    t += seconds;
  };
  bool first = true;
  for (const Step& step : plan) {
    const Pose& placed = poses[static_cast<size_t>(step.pose)];
    switch (step.kind) {
      case Step::Register:
        if (!first) {
          pose_from.emplace_back(t + 0.5 * kTurn_s, step.pose);
          travel_to(pen, kTurn_s);
        }
        first = false;
        for (uint32_t m : marks_seen[static_cast<size_t>(step.pose)]) {
          const Vec3& mark = marks[m];
          travel_to(placed(mark), kTravel_s);
          hold(d.mark_hold_s);
          command(t - 0.2, CommandKind::Mark, m, mark);
          ++stats.mark_touches;
        }
        travel_to(pen, 0.3);  // the pen lifted off the last mark
        command(t, CommandKind::Register);
        ++stats.registrations;
        break;
      case Step::Stroke: {
        std::vector<Vec3> world;
        for (const Vec3& p : step.points) world.push_back(placed(p));
        Polyline path = make_polyline(std::move(world));
        travel_to(path.points.front(), kTravel_s);
        hold(d.hold_s);
        const double move = SpeedProfile{path.arc.back(), d.speed_m_s, kAccel}.duration();
        timeline.push_back({Phase::Move, t, t + move, static_cast<int>(strokes.size()), pen, path.points.back()});
        t += move;
        pen = path.points.back();
        hold(d.hold_s * 2 / 3);
        strokes.push_back(std::move(path));
        ++stats.strokes;
        break;
      }
      case Step::Undo:
        travel_to(pen, kUndoWait_s);
        command(t, CommandKind::Undo);
        ++stats.undos;
        break;
      case Step::Hole:
        // The pen touches the face, unlit, and the pad's hole button is pressed.
        travel_to(placed(step.points.front()), kTravel_s);
        hold(d.mark_hold_s);
        command(t - 0.2, CommandKind::Hole, 0, step.points.front());
        ++stats.holes;
        break;
    }
  }
  std::vector<int> used;
  for (const Step& step : plan) used.push_back(step.pose);
  std::sort(used.begin(), used.end());
  stats.poses = static_cast<int>(std::unique(used.begin(), used.end()) - used.begin());
  stats.border_strokes = planned->border_strokes;
  stats.pieces = planned->pieces;
  stats.split_strokes = stats.strokes - stats.border_strokes;
  const double duration = t + 1.0;
  if (duration > 3600) return R::failure("the drawing would last more than an hour (" + std::to_string(duration) + " s)");
  timeline.push_back({Phase::Travel, t, std::numeric_limits<double>::infinity(), -1, pen, pen});

  auto pose_at = [&](double time) -> const Pose& {
    const auto it = std::upper_bound(pose_from.begin(), pose_from.end(), time,
                                     [](double v, const std::pair<double, int>& p) { return v < p.first; });
    return poses[static_cast<size_t>(std::prev(it)->second)];
  };
  Scene scene = [&](double time) { return pen_at(timeline, strokes, PenMotion{d.speed_m_s, kAccel}, time); };
  const Occluded occluded = [&](double time, const Vec3& light, const Vec3& centre) { return hidden(pose_at(time), light, centre); };
  std::vector<InputEvent> header = common_header("drawing", o);
  add_meta(header, "mesh", d.mesh_name + " height_m=" + format_double(d.height_m));
  add_meta(header, "drawing", "strokes=" + std::to_string(stats.strokes) + " undos=" + std::to_string(stats.undos) +
                                  " registrations=" + std::to_string(stats.registrations) + " curves=" +
                                  std::to_string(stats.curves_drawn) + "/" + std::to_string(stats.curves_total) +
                                  " speed_m_s=" + format_double(d.speed_m_s));
  SimulatedDrawing out;
  out.session = run_session(o, kDrawingScenario, *rig, duration, scene, occluded, std::move(header), commands);
  out.session.stats.strokes = stats.strokes;
  out.marks = marks;
  out.drawing = stats;
  return out;
}

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

DrawingNetwork drawing_network(const Mesh& m) {
  DrawingNetwork net;
  std::vector<uint32_t> curve_of(m.edge_slots(), 0);
  for (uint32_t v = 0; v < m.vertex_slots(); ++v) net.vertices.push_back(m.vertices.position[v]);
  for (uint32_t e = 0; e < m.edge_slots(); ++e) {
    if (!m.edge_alive(e)) continue;
    const std::span<const Vec3> points = m.polyline(e);
    curve_of[e] = static_cast<uint32_t>(net.curves.size());
    net.curves.push_back({m.edges.vertex[e][0], m.edges.vertex[e][1], {points.begin(), points.end()}, m.is_border_edge(e)});
  }
  for (uint32_t f = 0; f < m.face_slots(); ++f) {
    if (!m.face_alive(f)) continue;
    Chain& loop = net.faces.emplace_back();
    for (uint32_t oe : m.face_loop(f)) loop.push_back({curve_of[edge_of(oe)], !is_reversed(oe)});
  }
  return net;
}

}  // namespace fire::simulation
