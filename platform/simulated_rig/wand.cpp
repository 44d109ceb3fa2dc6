// The wand scene: two LEDs on a bar waved in front of the rig, for calibration.
#include "platform/simulated_rig/simulated_rig_detail.hpp"

namespace fire::simulation {
using namespace detail;

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
  Random motion(o.seed, stream_of(Scenario::Wand, Stream::Motion));
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
  return run_session(o, Scenario::Wand, *rig, w.duration_s, scene, {}, std::move(header));
}

}  // namespace fire::simulation
