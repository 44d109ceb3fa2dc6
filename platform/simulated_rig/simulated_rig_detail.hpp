#pragma once
// What the simulator's parts share (internal to the simulated rig here and the simulated person of
// tools/simulation/drawing.cpp): seeded random streams, both cameras run over a scene into a session, the
// object's triangles, and the pen moving along its strokes.
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "platform/simulated_rig/simulated_rig.hpp"

namespace fire::simulation::detail {

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
enum class Scenario : uint64_t { Wand = 1, Sketch = 2, Drawing = 3 };
enum class Stream : uint64_t { Rig, Clock, Stray, Motion, Noise0, Noise1, Timing0, Timing1, Occlusion0, Occlusion1, Burst };
inline uint64_t stream_of(Scenario scenario, Stream s) {
  return 64 * static_cast<uint64_t>(scenario) + static_cast<uint64_t>(s);
}

// The same pinhole-plus-radial model as Camera::project, written out here so that the simulator
// does not test the calibration with the calibration's own code.
tracking::Vec2 true_projection(const tracking::Camera& c, const Vec3& X);

using Triangles = std::vector<std::array<Vec3, 3>>;
// Ray-triangle intersection (Moller-Trumbore); the distance along `dir` or nothing.
std::optional<double> intersect(const Vec3& origin, const Vec3& dir, const std::array<Vec3, 3>& tri);
// Whether one of triangles [first, last) crosses the segment from + s dir, s in (0, len).
bool crossed(const Triangles& tris, size_t first, size_t last, const Vec3& from, const Vec3& dir, double len);
bool segment_blocked(const Triangles& tris, const Vec3& from, const Vec3& to);

// What one camera exposes at one instant: lit LEDs in the world, and the truth line to log.
struct SceneSample {
  std::vector<Vec3> lights;
  std::string truth_name;
  std::vector<double> truth_values;  // after device and exposure instant
};
using Scene = std::function<SceneSample(double t_s)>;

// Whether the object (or nothing, when empty) hides a light from a camera's centre at time t.
using Occluded = std::function<bool(double t_s, const Vec3& light, const Vec3& camera_centre)>;

// Runs both cameras over [0, duration) and writes the session: header facts, then every report
// in host arrival order, each followed by its truth, with `commands` (sorted by time) among them.
SimulatedSession run_session(const RigOptions& o, Scenario scenario, const SimulatedRig& rig, double duration_s, const Scene& scene,
                             const Occluded& occluded, std::vector<InputEvent> header, const std::vector<InputEvent>& commands = {});

// The header lines every scenario starts with, and one more `meta` line.
std::vector<InputEvent> common_header(const char* scenario, const RigOptions& o);
void add_meta(std::vector<InputEvent>& ev, const std::string& key, const std::string& text);

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
Polyline make_polyline(std::vector<Vec3> points);

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
                   double time);

}  // namespace fire::simulation::detail
