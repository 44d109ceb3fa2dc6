#include "systems/register/register.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include "engine/snapshot_fields.hpp"
#include "engine/text.hpp"

namespace fire {
namespace {

constexpr uint8_t kMeasuredMarksRecord = 2;

Vec3 mapped(const RegistrationState& s, const Vec3& p) { return s.transform ? Vec3(s.transform->R * p + s.transform->t) : p; }

// Where the pen rests at the command `e`: the mean of its samples over the last kRestWindowUs, or none
// (rejected, in words starting with `what`) when too few samples were seen or they spread too far.
std::optional<Vec3> resting_pen(const InputEvent& e, const RegistrationState& s, const std::string& what,
                                std::vector<Rejection>& rejections) {
  Vec3 mean = Vec3::Zero();
  size_t n = 0;
  for (const auto& [t, p] : s.recent)
    if (t > e.t_us - kRestWindowUs && t <= e.t_us) {
      mean += p;
      ++n;
    }
  if (n < kRestSamples) {
    rejections.push_back({e.t_us, e.line, what + "the pen was seen " + std::to_string(n) + " time(s) in the " +
                                              std::to_string(kRestWindowUs / 1000) + " ms before the command; rest it there (at least " +
                                              std::to_string(kRestSamples) + " samples)"});
    return std::nullopt;
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
                                              " (rms) about their mean while resting (at most " + format_mm(kRestSpread) +
                                              "); hold it still"});
    return std::nullopt;
  }
  return mean;
}

std::string mark_ids(const std::vector<MeasuredMark>& marks) {
  std::string ids;
  for (const MeasuredMark& m : marks) ids += (ids.empty() ? "" : ", ") + std::to_string(m.mark);
  return ids;
}

// A mark touched for the next registration: at its given coordinates (cmd mark N X Y Z) or its measured ones.
void touch_mark(const InputEvent& e, RegistrationState& s, std::vector<Rejection>& rejections) {
  const std::string what = "mark " + std::to_string(e.mark) + ": ";
  Vec3 model = e.p;
  if (e.command == CommandKind::MarkMeasured) {
    const MeasuredMark* m = s.measured_mark(e.mark);
    if (!m) {
      rejections.push_back({e.t_us, e.line, what + "not measured (" +
                                                (s.measured.empty() ? std::string("no mark is") : "marks " + mark_ids(s.measured) + " are") +
                                                "); measure it first (cmd measure N), or give its coordinates (cmd mark N X Y Z)"});
      return;
    }
    if (!s.transform) {
      rejections.push_back({e.t_us, e.line, what + "measured, but the object has no frame yet: the first cmd register makes it "
                                                   "from the table and the marks measured"});
      return;
    }
    model = m->p;
  }
  const std::optional<Vec3> rest = resting_pen(e, s, what, rejections);
  if (!rest) return;
  // A mark touched again replaces its earlier touch.
  std::erase_if(s.touched, [&](const MarkTouch& m) { return m.mark == e.mark; });
  s.touched.push_back({e.mark, *rest, model});
}

// Of `points`, the one nearer than kMarkSpacing to `p`, if any.
std::optional<size_t> too_near(const std::vector<Vec3>& points, const Vec3& p) {
  for (size_t k = 0; k < points.size(); ++k)
    if ((points[k] - p).norm() < kMarkSpacing) return k;
  return std::nullopt;
}

void measure_mark(const InputEvent& e, RegistrationState& s, std::vector<Rejection>& rejections) {
  const std::string what = "measure mark " + std::to_string(e.mark) + ": ";
  if (const MeasuredMark* m = s.measured_mark(e.mark)) {
    rejections.push_back({e.t_us, e.line, what + "measured already (line " + std::to_string(m->line) +
                                              "); to register on it, touch it with cmd mark " + std::to_string(e.mark) +
                                              ", or measure another mark under a new number"});
    return;
  }
  const std::optional<Vec3> rest = resting_pen(e, s, what, rejections);
  if (!rest) return;
  const Vec3 p = mapped(s, *rest);
  std::vector<Vec3> others;
  for (const MeasuredMark& m : s.measured) others.push_back(m.p);
  if (const std::optional<size_t> k = too_near(others, p)) {
    rejections.push_back({e.t_us, e.line, what + "the pen rests " + format_mm((others[*k] - p).norm()) + " from mark " +
                                              std::to_string(s.measured[*k].mark) + " (at most " + format_mm(kMarkSpacing) +
                                              " apart): the same mark touched twice? Marks must be further apart"});
    return;
  }
  s.measured.push_back({e.mark, p, e.line});
  if (!s.rounds.empty()) s.rounds.back().push_back({e.mark, *rest});
}

void touch_table(const InputEvent& e, RegistrationState& s, std::vector<Rejection>& rejections) {
  const std::string what = "table: ";
  if (s.transform) {
    rejections.push_back({e.t_us, e.line, what + "the object's frame is made already (registration at line " +
                                              std::to_string(s.done.back().line) + "); table touches only make the first"});
    return;
  }
  const std::optional<Vec3> rest = resting_pen(e, s, what, rejections);
  if (!rest) return;
  if (const std::optional<size_t> k = too_near(s.table, *rest)) {
    rejections.push_back({e.t_us, e.line, what + "the pen rests " + format_mm((s.table[*k] - *rest).norm()) +
                                              " from table touch " + std::to_string(*k + 1) + " (at least " + format_mm(kMarkSpacing) +
                                              " apart); touch the table at points around the object"});
    return;
  }
  s.table.push_back(*rest);
}

struct Spread {
  Vec3 centre = Vec3::Zero();
  Eigen::Matrix3d axes;     // columns: the principal directions, the widest last
  double off_line = 0;      // the farthest point from the widest direction's line through the centre
  double off_plane_rms = 0;  // RMS distance from the plane of the two widest directions
};

Spread spread_of(const std::vector<Vec3>& points) {
  Spread out;
  for (const Vec3& p : points) out.centre += p;
  out.centre /= double(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Vec3& p : points) scatter += (p - out.centre) * (p - out.centre).transpose();
  out.axes = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors();
  double squared = 0;
  for (const Vec3& p : points) {
    const Vec3 d = p - out.centre;
    out.off_line = std::max(out.off_line, (d - d.dot(out.axes.col(2)) * out.axes.col(2)).norm());
    squared += std::pow(d.dot(out.axes.col(0)), 2);
  }
  out.off_plane_rms = std::sqrt(squared / double(points.size()));
  return out;
}

// The first registration on measured marks: the object's frame from the table and the marks (register.hpp).
void make_frame(const InputEvent& e, RegistrationState& s, std::vector<Rejection>& rejections) {
  auto reject = [&](const std::string& why) {
    rejections.push_back({e.t_us, e.line, "register: " + why + "; the touches are kept"});
  };
  if (s.table.size() < kTableTouches) {
    reject("the object's frame needs " + std::to_string(kTableTouches) + " touches on the table around the object (cmd table), " +
           std::to_string(s.table.size()) + " made");
    return;
  }
  if (s.measured.size() < 3) {
    reject("the object's frame needs at least 3 measured marks (cmd measure N), " + std::to_string(s.measured.size()) + " measured");
    return;
  }
  const Spread table = spread_of(s.table);
  if (table.off_line < kMarkSpacing) {
    reject("the table touches lie on a line (the farthest " + format_mm(table.off_line) + " from it, at least " +
           format_mm(kMarkSpacing) + "): touch the table at points around the object");
    return;
  }
  std::vector<Vec3> marks;
  for (const MeasuredMark& m : s.measured) marks.push_back(m.p);
  const Spread spread = spread_of(marks);
  if (spread.off_line < kMarkSpacing) {
    reject("the measured marks lie on a line (the farthest " + format_mm(spread.off_line) + " from it, at least " +
           format_mm(kMarkSpacing) + "): measure a mark off that line");
    return;
  }
  // The cameras look down on the table: its normal toward camera 0, at the rig frame's origin.
  Vec3 up = table.axes.col(0);
  if (up.dot(-table.centre) < 0) up = -up;
  for (const MeasuredMark& m : s.measured)
    if (const double height = up.dot(m.p - table.centre); height < -kMarkSpacing) {
      reject("mark " + std::to_string(m.mark) + " lies " + format_mm(-height) + " below the table touched: measure it again, "
             "or touch the table where the object stands");
      return;
    }
  Vec3 x = Vec3::UnitX() - up.x() * up;
  if (x.norm() < 0.1) x = Vec3::UnitY() - up.y() * up;  // camera 0 looks along the table
  x.normalize();
  Eigen::Matrix3d R;
  R.row(0) = x.transpose();
  R.row(1) = up.cross(x).transpose();
  R.row(2) = up.transpose();
  const Vec3& centroid = spread.centre;
  const Vec3 origin = centroid - up.dot(centroid - table.centre) * up;
  tracking::RigidTransform T;
  T.R = R;
  T.t = -R * origin;
  T.rms_residual = table.off_plane_rms;
  s.transform = T;
  s.frame_transform = T;
  s.rounds.assign(1, {});
  for (MeasuredMark& m : s.measured) {
    s.rounds[0].push_back({m.mark, m.p});
    m.p = mapped(s, m.p);
  }
  s.done.push_back({e.line, uint32_t(s.measured.size()), T.rms_residual, true});
}

// The measured marks and every round's motion (the frame's held), alternated to a least-squares fit of all
// the rests: each round's motion on the marks (Umeyama), each mark at the mean of where the rounds put it.
// Returns the latest round's motion.
tracking::RigidTransform refine_measured(RegistrationState& s, const tracking::RigidTransform& latest) {
  std::vector<tracking::RigidTransform> motions(s.rounds.size(), *s.frame_transform);
  motions.back() = latest;
  // Each rest's mark in `measured` (a round holds rests on measured marks only).
  std::vector<std::vector<size_t>> at(s.rounds.size());
  for (size_t r = 0; r < s.rounds.size(); ++r)
    for (const MarkRest& rest : s.rounds[r])
      at[r].push_back(size_t(s.measured_mark(rest.mark) - s.measured.data()));
  for (int sweep = 0; sweep < kRefineSweeps; ++sweep) {
    for (size_t r = 1; r < s.rounds.size(); ++r) {
      std::vector<Vec3> rests, marks;
      for (size_t k = 0; k < s.rounds[r].size(); ++k) {
        rests.push_back(s.rounds[r][k].rest);
        marks.push_back(s.measured[at[r][k]].p);
      }
      if (Result<tracking::RigidTransform> T = tracking::register_rigid(rests, marks)) motions[r] = *T;
    }
    std::vector<Vec3> sum(s.measured.size(), Vec3::Zero());
    std::vector<int> count(s.measured.size(), 0);
    for (size_t r = 0; r < s.rounds.size(); ++r)
      for (size_t k = 0; k < s.rounds[r].size(); ++k) {
        sum[at[r][k]] += motions[r].R * s.rounds[r][k].rest + motions[r].t;
        ++count[at[r][k]];
      }
    for (size_t m = 0; m < s.measured.size(); ++m)
      if (count[m] > 0) s.measured[m].p = sum[m] / double(count[m]);
  }
  return motions.back();
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
  if (s.touched.empty() && !s.transform && !s.measured.empty()) {
    make_frame(e, s, rejections);
    return;
  }
  if (s.touched.size() < 3 && s.transform && !s.measured.empty()) {
    reject(std::to_string(s.touched.size()) + " mark(s) touched since the last registration, a registration needs at least 3: " +
           "touch 3 of the marks measured (" + mark_ids(s.measured) + ") that both cameras see (cmd mark N); where fewer face them, " +
           "turn the object back, measure marks (cmd measure N) on the side that will face them, and turn it again");
    return;
  }
  if (s.touched.size() < 3) {
    reject(std::to_string(s.touched.size()) + " mark(s) touched since the last registration, a registration needs at least 3 " +
           "(rest the pen on each mark and log cmd mark N X Y Z, or measure the marks with cmd table and cmd measure N)");
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
  const bool first = !s.transform;
  const bool all_measured = std::all_of(s.touched.begin(), s.touched.end(), [&](const MarkTouch& m) {
    const MeasuredMark* measured = s.measured_mark(m.mark);
    return measured && measured->p == m.model;
  });
  if (s.frame_transform && all_measured) {
    std::vector<MarkRest>& round = s.rounds.emplace_back();
    for (const MarkTouch& m : s.touched) round.push_back({m.mark, m.measured});
    T = refine_measured(s, *T);
  }
  s.transform = *T;
  if (first)  // marks measured before it wait for it
    for (MeasuredMark& m : s.measured) m.p = mapped(s, m.p);
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
  const bool touch = e.kind == EventKind::Command && is_touch_command(e.command);
  const bool registering = touch || (e.kind == EventKind::Command && e.command == CommandKind::Register);
  if (registering && !tracked) {
    const char* name = e.command == CommandKind::Register ? "register"
                       : e.command == CommandKind::Table  ? "table"
                       : e.command == CommandKind::Measure ? "measure"
                                                           : "mark";
    rejections.push_back({e.t_us, e.line, std::string(name) + ": registration needs a tracked pen (a log of device reports, replayed with --rig)"});
  } else if (registering) {
    if (touch) {
      if (e.command == CommandKind::Table) touch_table(e, s, rejections);
      else if (e.command == CommandKind::Measure) measure_mark(e, s, rejections);
      else touch_mark(e, s, rejections);
      // The pen rests on a mark or the table: what it drew since it went down, and draws until it lifts, is a touch. A pen
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

const MeasuredMark* RegistrationState::measured_mark(uint32_t mark) const {
  for (const MeasuredMark& m : measured)
    if (m.mark == mark) return &m;
  return nullptr;
}

std::vector<std::string> describe_registration(const RegistrationState& s) {
  std::vector<std::string> out;
  for (size_t k = 0; k < s.done.size(); ++k) {
    const Registration& r = s.done[k];
    const std::string head = "registration " + std::to_string(k + 1) + " (line " + std::to_string(r.line) + "): ";
    if (r.measured_frame)
      out.push_back(head + "the object's frame from the table (touches " + format_mm(r.residual) + " rms from their plane) and " +
                    std::to_string(r.marks) + " marks measured");
    else
      out.push_back(head + std::to_string(r.marks) + " marks, residual " + format_mm(r.residual));
  }
  if (!s.measured.empty())
    out.push_back(std::to_string(s.measured.size()) + " mark(s) measured: " + mark_ids(s.measured) +
                  (s.transform ? "" : " (no frame made yet: cmd register makes it)"));
  if (s.touches_dropped)
    out.push_back(std::to_string(s.touches_dropped) + " touch(es) of the pen, on a mark or never " + format_mm(kTouchRadius) +
                  " from where it went down: not drawn");
  if (!s.touched.empty())
    out.push_back(std::to_string(s.touched.size()) + " mark(s) touched after the last registration, not registered");
  return out;
}

namespace {

template <class Io, class Transform>
void transform_fields(Io& io, Transform& T) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) io(T.R(r, c));
  io(T.t);
  io(T.rms_residual);
}

// The state as it lies in a snapshot (engine/snapshot_fields.hpp); S is const when writing.
template <class Io, class S>
void state_fields(Io& io, S& s) {
  io.optional(s.transform, [&](auto& T) { transform_fields(io, T); });
  io.sequence(s.touched, [&](auto& m) {
    io(m.mark);
    io(m.measured);
    io(m.model);
  });
  io(s.recent);
  io.flag(s.stroke_open);
  io.flag(s.stroke_released);
  io.sequence(s.held, [&](auto& e) {
    io(e.t_us);
    io.template as<uint8_t>(e.kind);
    io(e.p);
    io(e.snap);
    io(e.line);
    io.check(e.kind == EventKind::Down || e.kind == EventKind::Pen);
  });
  io.sequence(s.done, [&](auto& r) {
    io(r.line);
    io(r.marks);
    io(r.residual);
  });
  io(s.touches_dropped);
  // Since marks are measured by touch; older snapshots end above.
  io.since(kMeasuredMarksRecord, [&] {
    io(s.table);
    io.sequence(s.measured, [&](auto& m) {
      io(m.mark);
      io(m.p);
      io(m.line);
    });
    for (auto& r : s.done) io.flag(r.measured_frame);
    io.optional(s.frame_transform, [&](auto& T) { transform_fields(io, T); });
    io.sequence(s.rounds, [&](auto& round) {
      io.sequence(round, [&](auto& m) {
        io(m.mark);
        io(m.rest);
        io.check(s.measured_mark(m.mark) != nullptr);
      });
    });
  });
}

}  // namespace

void RegistrationState::save(SnapshotWriter& out) const {
  SnapshotPut put{out};
  state_fields(put, *this);
}

bool RegistrationState::load(SnapshotReader& in) {
  *this = {};
  SnapshotGet get{in};
  state_fields(get, *this);
  return in.ok();
}

}  // namespace fire
