// The pen moving along its strokes: lit while it draws or rests on a stroke's ends, unlit between strokes.
#include <algorithm>
#include <cmath>

#include "platform/simulated_rig/simulated_rig_detail.hpp"

namespace fire::simulation::detail {

Polyline make_polyline(std::vector<Vec3> points) {
  Polyline p;
  p.arc.push_back(0);
  for (size_t i = 1; i < points.size(); ++i) p.arc.push_back(p.arc.back() + (points[i] - points[i - 1]).norm());
  p.points = std::move(points);
  return p;
}

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

}  // namespace fire::simulation::detail
