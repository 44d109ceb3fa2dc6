#include "systems/register/register.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include "engine/text.hpp"

namespace fire {
namespace {

Vec3 mapped(const RegistrationState& s, const Vec3& p) { return s.transform ? Vec3(s.transform->R * p + s.transform->t) : p; }

void touch_mark(const InputEvent& e, RegistrationState& s, std::vector<Rejection>& rejections) {
  const std::string what = "mark " + std::to_string(e.mark) + ": ";
  Vec3 mean = Vec3::Zero();
  size_t n = 0;
  for (const auto& [t, p] : s.recent)
    if (t > e.t_us - kRestWindowUs && t <= e.t_us) {
      mean += p;
      ++n;
    }
  if (n < kRestSamples) {
    rejections.push_back({e.t_us, e.line, what + "the pen was seen " + std::to_string(n) + " time(s) in the " +
                                              std::to_string(kRestWindowUs / 1000) + " ms before the command; rest it on the mark (at least " +
                                              std::to_string(kRestSamples) + " samples)"});
    return;
  }
  mean /= double(n);
  // RMS, not the farthest sample: a resting pen far from both cameras flickers in depth between two levels
  // a pixel's step apart, and its mean is still where it rests; a pen that slides or wobbles spreads wider.
  double squared = 0;
  for (const auto& [t, p] : s.recent)
    if (t > e.t_us - kRestWindowUs && t <= e.t_us) squared += (p - mean).squaredNorm();
  const double spread = std::sqrt(squared / double(n));
  if (spread > kRestSpread) {
    rejections.push_back({e.t_us, e.line, what + "the pen's samples spread " + format_mm(spread) +
                                              " (rms) about their mean while resting on the mark (at most " + format_mm(kRestSpread) +
                                              "); hold it still"});
    return;
  }
  // A mark touched again replaces its earlier touch.
  std::erase_if(s.touched, [&](const MarkTouch& m) { return m.mark == e.mark; });
  s.touched.push_back({e.mark, mean, e.p});
}

// The rigid motion of the marks touched, but the one at `left_out` (none left out by default).
Result<tracking::RigidTransform> fit_marks(const std::vector<MarkTouch>& touched, size_t left_out = SIZE_MAX) {
  std::vector<Vec3> measured, model;
  for (size_t i = 0; i < touched.size(); ++i)
    if (i != left_out) {
      measured.push_back(touched[i].measured);
      model.push_back(touched[i].model);
    }
  return tracking::register_rigid(measured, model);
}

struct OddMark {
  uint32_t mark = 0;
  double distance = 0;  // metres, from where the other marks' motion puts it
};

// The mark without which the others fit a rigid motion best, when they fit within kMaxResidual and are at
// least three: the mark a registration's rejection names, the likeliest to have been touched wrong.
std::optional<OddMark> odd_mark(const std::vector<MarkTouch>& touched) {
  if (touched.size() < 4) return std::nullopt;
  std::optional<OddMark> odd;
  double best_residual = kMaxResidual;
  for (size_t left_out = 0; left_out < touched.size(); ++left_out) {
    const Result<tracking::RigidTransform> T = fit_marks(touched, left_out);
    if (!T || !(T->rms_residual <= best_residual)) continue;
    best_residual = T->rms_residual;
    const MarkTouch& m = touched[left_out];
    odd = OddMark{m.mark, (T->R * m.measured + T->t - m.model).norm()};
  }
  return odd;
}

void register_marks(const InputEvent& e, RegistrationState& s, std::vector<Rejection>& rejections) {
  auto reject = [&](const std::string& why) {
    rejections.push_back({e.t_us, e.line, "register: " + why + "; the marks touched are kept"});
  };
  if (s.touched.size() < 3) {
    reject(std::to_string(s.touched.size()) + " mark(s) touched since the last registration, a registration needs at least 3 " +
           "(rest the pen on each mark and log cmd mark N X Y Z)");
    return;
  }
  Result<tracking::RigidTransform> T = fit_marks(s.touched);
  if (!T) {
    reject(T.error());
    return;
  }
  if (!(T->rms_residual <= kMaxResidual)) {
    const std::string misfit = "the marks do not fit one rigid motion (residual " + format_mm(T->rms_residual) + ", at most " +
                               format_mm(kMaxResidual) + "): ";
    if (const std::optional<OddMark> odd = odd_mark(s.touched))
      reject(misfit + "mark " + std::to_string(odd->mark) + " fits worst, " + format_mm(odd->distance) + " from where the other " +
             std::to_string(s.touched.size() - 1) + " put it; touch it again (it was touched in the wrong place, logged with " +
             "the wrong number or coordinates, or touched before the object moved)");
    else
      reject(misfit + "a mark was touched in the wrong place or logged with the wrong number or coordinates");
    return;
  }
  s.transform = *T;
  s.done.push_back({e.line, uint32_t(s.touched.size()), T->rms_residual});
  s.touched.clear();
}

void release(RegistrationState& s, std::vector<InputEvent>& out) {
  s.stroke_released = true;
  for (InputEvent& h : s.held) {
    if (h.kind == EventKind::Pen) h.p = mapped(s, h.p);
    out.push_back(std::move(h));
  }
  s.held.clear();
}

// What one event of the frame does: see register_system.
void take(const InputEvent& e, bool tracked, RegistrationState& s, std::vector<InputEvent>& out,
          std::vector<Rejection>& rejections) {
  const bool registering = e.kind == EventKind::Command && (e.command == CommandKind::Mark || e.command == CommandKind::Register);
  if (registering && !tracked) {
    rejections.push_back({e.t_us, e.line, std::string(e.command == CommandKind::Mark ? "mark" : "register") +
                                            ": registration needs a tracked pen (a log of device reports, replayed with --rig)"});
  } else if (registering) {
    if (e.command == CommandKind::Mark) {
      touch_mark(e, s, rejections);
      // The pen rests on a mark: what it drew since it went down, and draws until it lifts, is a touch. A pen
      // far from both cameras flickers in depth by more than kTouchRadius even at rest, so part of it may have
      // gone to the sketch system already, which the command tells to drop.
      if (s.stroke_open) {
        if (s.stroke_released) out.push_back(e);
        s.stroke_released = false;
        s.held.clear();
      }
    } else {
      register_marks(e, s, rejections);
    }
  } else if (e.kind == EventKind::Hid || e.kind == EventKind::Truth || e.kind == EventKind::Meta) {
    // the triangulation system's, or not for replay
  } else if (!tracked || e.kind == EventKind::Command) {
    out.push_back(e);
  } else if (e.kind == EventKind::Pen) {
    s.recent.emplace_back(e.t_us, e.p);
    const int64_t oldest = e.t_us - kRestWindowUs;
    std::erase_if(s.recent, [&](const auto& r) { return r.first <= oldest; });
    if (!s.stroke_open || s.stroke_released) {
      out.push_back(e);
      out.back().p = mapped(s, e.p);
      return;
    }
    if (s.held.empty()) return;  // after a mark touched
    const bool left = s.held.size() >= 2 && (e.p - s.held[1].p).norm() > kTouchRadius;  // held[0] is the Down
    s.held.push_back(e);
    if (left) release(s, out);
  } else if (e.kind == EventKind::Down) {
    s.stroke_open = true;
    s.stroke_released = false;
    s.held.assign(1, e);
  } else {  // Up
    if (s.stroke_open && !s.stroke_released)
      ++s.touches_dropped;  // the pen rested on a mark, or never left its first sample's neighbourhood
    else
      out.push_back(e);
    s.stroke_open = s.stroke_released = false;
    s.held.clear();
  }
}

}  // namespace

void register_system(const std::vector<InputEvent>& frame_events, const std::vector<InputEvent>& pen_events, bool tracked,
                     RegistrationState& s, std::vector<InputEvent>& out, std::vector<Rejection>& rejections) {
  out.clear();
  for (const InputEvent& e : frame_events) take(e, tracked, s, out, rejections);
  for (const InputEvent& e : pen_events) take(e, tracked, s, out, rejections);
}

std::vector<std::string> describe_registration(const RegistrationState& s) {
  std::vector<std::string> out;
  for (size_t k = 0; k < s.done.size(); ++k)
    out.push_back("registration " + std::to_string(k + 1) + " (line " + std::to_string(s.done[k].line) + "): " +
                  std::to_string(s.done[k].marks) + " marks, residual " + format_mm(s.done[k].residual));
  if (s.touches_dropped)
    out.push_back(std::to_string(s.touches_dropped) + " touch(es) of the pen, on a mark or never " + format_mm(kTouchRadius) +
                  " from where it went down: not drawn");
  if (!s.touched.empty())
    out.push_back(std::to_string(s.touched.size()) + " mark(s) touched after the last registration, not registered");
  return out;
}

void RegistrationState::save(SnapshotWriter& out) const {
  out.put(uint8_t(transform.has_value()));
  if (transform) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) out.put(transform->R(r, c));
    out.put(transform->t);
    out.put(transform->rms_residual);
  }
  out.put(uint64_t(touched.size()));
  for (const MarkTouch& m : touched) {
    out.put(m.mark);
    out.put(m.measured);
    out.put(m.model);
  }
  out.put(recent);
  out.put(uint8_t(stroke_open));
  out.put(uint8_t(stroke_released));
  out.put(uint64_t(held.size()));
  for (const InputEvent& e : held) {
    out.put(e.t_us);
    out.put(uint8_t(e.kind));
    out.put(e.p);
    out.put(e.snap);
    out.put(e.line);
  }
  out.put(uint64_t(done.size()));
  for (const Registration& r : done) {
    out.put(r.line);
    out.put(r.marks);
    out.put(r.residual);
  }
  out.put(touches_dropped);
}

bool RegistrationState::load(SnapshotReader& in) {
  *this = {};
  uint8_t has = 0, open = 0, released = 0;
  in.get(has);
  if (has) {
    transform.emplace();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) in.get(transform->R(r, c));
    in.get(transform->t);
    in.get(transform->rms_residual);
  }
  uint64_t n = 0;
  in.get(n);
  for (uint64_t k = 0; k < n && in.ok(); ++k) {
    MarkTouch& m = touched.emplace_back();
    in.get(m.mark);
    in.get(m.measured);
    in.get(m.model);
  }
  in.get(recent);
  in.get(open);
  in.get(released);
  stroke_open = open;
  stroke_released = released;
  in.get(n);
  for (uint64_t k = 0; k < n && in.ok(); ++k) {
    InputEvent& e = held.emplace_back();
    uint8_t kind = 0;
    in.get(e.t_us);
    in.get(kind);
    in.get(e.p);
    in.get(e.snap);
    in.get(e.line);
    if (kind != uint8_t(EventKind::Down) && kind != uint8_t(EventKind::Pen)) in.fail();
    e.kind = EventKind(kind);
  }
  in.get(n);
  for (uint64_t k = 0; k < n && in.ok(); ++k) {
    Registration& r = done.emplace_back();
    in.get(r.line);
    in.get(r.marks);
    in.get(r.residual);
  }
  in.get(touches_dropped);
  if (has > 1 || open > 1 || released > 1) in.fail();
  return in.ok();
}

}  // namespace fire
