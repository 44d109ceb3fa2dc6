#include "systems/triangulate/triangulate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fire {
namespace {

using tracking::CameraFrames;
using tracking::CameraReport;
using tracking::Interpolated;
using tracking::PenSample;

constexpr double kNominalPeriodUs = kReportPeriodUs;  // the gaps say it better once seen
constexpr size_t kPeriodGaps = 63;           // arrival gaps the period is the median of
constexpr size_t kMinPeriodGaps = 8;
constexpr double kRateTolerance = 1.25;        // a report rate outside 80 to 125 Hz is said in words
constexpr double kPendingTimeout = 1.5;      // periods after which no later report can renumber the waiting ones
// Camera 1 has not reported an instant this long after it (a lost report, latency and the wait for the
// next report included): triangulate without it.
constexpr double kCameraHorizonUs = 120'000;
constexpr int64_t kSilenceUs = 500'000;     // a remote this long without a report has stopped (a 100 Hz stream)
constexpr int64_t kKeepUs = 30'000'000;      // trailing reports kept per camera (the offset's window)
constexpr size_t kTrimChunk = 512;           // reports dropped from a window at once
constexpr uint64_t kOffsetEvery = 200;       // camera 0 reports between two estimates of the time offset
constexpr size_t kMaxMoving = 600;           // moving blobs the estimate uses (the newest)
constexpr double kFirstSearchUs = 50'000;    // the first estimate looks this far either side of zero...
constexpr double kNextSearchUs = 10'000;     // ... later ones this far either side of the value in use

constexpr double kJumpGate_m = 0.02;      // pen positions this far apart are different things
// A stroke's first fit and one with a light that only appears in camera 1's next frame, farther apart than a
// pixel's step in depth (the pen far from both cameras), are two things: the pen and a reflection.
constexpr double kStartAgree_m = 0.004;
constexpr double kMaxPenSpeed_m_s = 5.0;  // a hand moves the pen no faster
constexpr double kBridgeSpeed_m_s = 1.0;  // a drawing hand, while both cameras lose the pen, moves it no faster
constexpr double kSpeedUp_m_s = 1.0;      // a hand speeds the pen up by no more than this from one frame to the next
constexpr double kRestingSpeed_m_s = 0.05;  // a pen slower than this (filtered) is resting, not drawing
constexpr double kFollowStep_px = 40;     // the pen's blob moves less than this between two frames of a camera
// Of the pairs that fit where the pen could be, the nearer wins unless it is worse off its epipolar line
// than the pen's own pixel noise explains. A light that shone merged with the pen's blob and split from it
// fits a few millimetres off and a pixel or more off the line; once taken, the pen is what looks like the
// light beside it, and the light then holds the lifted pen down. A pixel of misfit counts as this distance:
// a few frames' motion, against the quarter pixel of a true pair's noise.
constexpr double kMisfitDistance_m = 0.02;
constexpr double kOnsetReachUs = 1'000'000;  // how far back a light's first frame is looked for

// The median of the recent gaps, taken when a gap is added: every report and frame reads it.
double median_period(const std::deque<double>& gaps_us) {
  if (gaps_us.size() < kMinPeriodGaps) return kNominalPeriodUs;
  std::vector<double> g(gaps_us.begin(), gaps_us.end());
  const auto mid = g.begin() + static_cast<std::ptrdiff_t>(g.size() / 2);
  std::nth_element(g.begin(), mid, g.end());
  return *mid;
}

double period_of(const CameraWindow& w) { return w.period_us; }

void erase_front(CameraWindow& w, size_t n) {
  CameraFrames& f = w.frames;
  const auto d = static_cast<std::ptrdiff_t>(n);
  f.t_us.erase(f.t_us.begin(), f.t_us.begin() + d);
  f.line.erase(f.line.begin(), f.line.begin() + d);
  f.t_frame_us.erase(f.t_frame_us.begin(), f.t_frame_us.begin() + d);
  f.blob_count.erase(f.blob_count.begin(), f.blob_count.begin() + d);
  f.blobs.erase(f.blobs.begin(), f.blobs.begin() + d);
  w.links.erase(w.links.begin(), w.links.begin() + d);
  w.first_index += n;
}

// The oldest waiting report's frame number is settled and its instant fixed on the camera's clock.
void fix_oldest(CameraWindow& w, int camera, TriangulateState& state, const TrackingRig& rig) {
  const CameraReport r = w.waiting.front();
  std::array<double, tracking::FrameNumbering::kLookahead + 1> arrivals;
  const size_t m = std::min(w.waiting.size(), arrivals.size());
  for (size_t i = 0; i < m; ++i) arrivals[i] = static_cast<double>(w.waiting[i].t_us - w.origin_us);
  const double previous = w.frames.size() > 0 ? static_cast<double>(w.frames.t_us.back() - w.origin_us)
                                              : std::numeric_limits<double>::quiet_NaN();
  const double number = w.clock.settle(std::span<const double>(arrivals.data(), m), previous);
  w.waiting.pop_front();
  double t_frame = static_cast<double>(w.origin_us) + w.clock.instant(number);
  CameraFrames& f = w.frames;
  if (f.size() > 0) t_frame = std::max(t_frame, f.t_frame_us.back() + 1.0);
  f.t_us.push_back(r.t_us);
  f.line.push_back(r.line);
  f.t_frame_us.push_back(t_frame);
  f.blob_count.push_back(r.blob_count);
  f.blobs.push_back(r.blobs);
  w.links.emplace_back();
  w.links.back().fill(-1);
  if (f.size() < 2) return;
  const size_t k = f.size() - 2;
  w.links[k] = tracking::link_to_next(f, k);
  if (camera != 0) return;
  // Camera 0's moving blobs carry the time offset; resting ones fit every offset alike.
  ++state.cam0_fixed;
  if (f.t_frame_us[k + 1] - f.t_frame_us[k] > tracking::kMaxInterpolationGap * period_of(w)) return;
  for (int i = 0; i < f.blob_count[k]; ++i) {
    const int8_t next = w.links[k][i];
    if (next < 0 || (f.blobs[k + 1][next] - f.blobs[k][i]).norm() < tracking::kMovingPx) continue;
    state.moving.push_back({f.t_frame_us[k], rig.cam0.undistort_normalized(f.blobs[k][i])});
    if (state.moving.size() > kMaxMoving) state.moving.pop_front();
  }
  // Older than camera 1's window: nothing left to compare them with.
  while (!state.moving.empty() && f.t_frame_us[k] - state.moving.front().t_us > static_cast<double>(kKeepUs))
    state.moving.pop_front();
}

// The camera frame whose instant is the last at or before t (none before the first).
std::optional<size_t> frame_at_or_before(const CameraFrames& f, double t) {
  const auto it = std::upper_bound(f.t_frame_us.begin(), f.t_frame_us.end(), t);
  if (it == f.t_frame_us.begin()) return std::nullopt;
  return static_cast<size_t>(it - f.t_frame_us.begin()) - 1;
}

struct Followed {
  Vec3 position;
  Vec2 px;
};

// While only one camera sees the pen, the pen lies on that camera's ray through its blob: the point of
// the ray nearest the pen's last position, if within `gate` of it, from the blob nearest the pen's last
// pixel in that camera. A stray reflection elsewhere in the image is never taken for the pen.
std::optional<Followed> follow_on_ray(const tracking::Camera& cam, std::span<const Vec2> blobs, const Vec2& last_px,
                                      const Vec3& last, double gate) {
  std::optional<Followed> best;
  double best_step = kFollowStep_px;
  for (const Vec2& px : blobs) {
    const double step = (px - last_px).norm();
    if (step > best_step) continue;
    const Vec3 c = cam.centre(), d = cam.ray(px);
    const Vec3 x = c + d * std::max(0.0, d.dot(last - c));
    if ((x - last).norm() > gate) continue;
    best_step = step;
    best = Followed{x, px};
  }
  return best;
}

// How far the pen may be from where it was last seen after `dt_us`, moving at `speed_m_s` (filtered): over a
// short gap, up to twice as fast and kSpeedUp_m_s more, as a flick starts, but no faster than a hand moves it;
// over a longer one the pen was hidden while a drawing hand went on, which is slower. A resting pen does not
// jump centimetres in a frame: a light level with it that lights as it goes out fits that far off.
double reach_m(double dt_us, int64_t short_gap_us, double speed_m_s) {
  const double speed = dt_us <= static_cast<double>(short_gap_us)
                           ? std::min(kMaxPenSpeed_m_s, 2 * speed_m_s + kSpeedUp_m_s)
                           : kBridgeSpeed_m_s;
  return kJumpGate_m + speed * dt_us * 1e-6;
}

// The blob of a camera's frame m - 1 whose link goes on to blob b of frame m (links are mutual, so at most
// one does), or -1: b began to shine in frame m.
int linked_from(const CameraWindow& w, size_t m, int b) {
  for (int i = 0; i < w.frames.blob_count[m - 1]; ++i)
    if (w.links[m - 1][i] == b) return i;
  return -1;
}

// Whether blob b of a camera's frame j continues, link by link, a light that shone beside the pen in the
// camera's last frame at or before `seen_t` (the pen there being the blob nearest `pen_px`): a reflection
// next to the pen fits the pen's ray as well once the pen is lifted, and following it would hold the pen
// down until it is put down elsewhere, joining two strokes.
bool beside_pen(const CameraWindow& w, size_t j, int b, double seen_t, const Vec2& pen_px) {
  const CameraFrames& f = w.frames;
  int blob = b;
  size_t m = j;
  while (blob >= 0 && m > 0 && f.t_frame_us[m] > seen_t) {
    blob = linked_from(w, m, blob);
    --m;
  }
  if (blob < 0 || f.t_frame_us[m] > seen_t || f.blob_count[m] < 2) return false;
  int nearest = 0;
  for (int i = 1; i < f.blob_count[m]; ++i)
    if ((f.blobs[m][i] - pen_px).norm() < (f.blobs[m][nearest] - pen_px).norm()) nearest = i;
  return blob != nearest;
}

// When blob b of a camera's frame j began to shine: the instant of the first frame of its chain of links,
// followed back no farther than kOnsetReachUs (nothing if it shone longer, or since the window began).
std::optional<double> lit_since(const CameraWindow& w, size_t j, int b) {
  const CameraFrames& f = w.frames;
  int blob = b;
  for (size_t m = j; m > 0 && f.t_frame_us[j] - f.t_frame_us[m - 1] <= kOnsetReachUs; --m) {
    const int from = linked_from(w, m, blob);
    if (from < 0) return f.t_frame_us[m];
    blob = from;
  }
  return std::nullopt;
}

// The blobs of a camera's frame j that may be the pen: not one beside it.
struct Candidates {
  std::array<Vec2, kIrSlots> px;
  int count = 0;
};
Candidates maybe_pen(const CameraWindow& w, size_t j, double seen_t, const Vec2& pen_px) {
  Candidates out;
  for (int b = 0; b < w.frames.blob_count[j]; ++b)
    if (!beside_pen(w, j, b, seen_t, pen_px)) out.px[size_t(out.count++)] = w.frames.blobs[j][b];
  return out;
}

// Stamped with the line of camera 0's report it came from, so a rejection names a line of the log.
InputEvent pen_event(int64_t t_us, uint32_t line, EventKind kind, const Vec3& p = Vec3::Zero()) {
  InputEvent e;
  e.t_us = t_us;
  e.line = line;
  e.kind = kind;
  e.p = p;
  return e;
}

void end_stroke(TriangulateState& s, std::vector<InputEvent>& out) {
  if (s.stroke_open) out.push_back(pen_event(s.last_sample_t_us, s.last_sample_line, EventKind::Up));
  s.down = false;
  s.stroke_open = false;
  s.lost_now = false;
}

// One camera 0 report (index k in its window): the pen's state machine of PenTrackOptions.
void track_frame(size_t k, const TrackingRig& rig, TriangulateState& s, std::vector<InputEvent>& out,
                 std::vector<PenSample>* samples) {
  const tracking::PenTrackOptions& options = rig.options;
  const CameraFrames& f0 = s.cameras[0].frames;
  const CameraWindow& w1 = s.cameras[1];
  const CameraFrames& f1 = w1.frames;
  const double t = f0.t_frame_us[k];
  const double t1 = t + s.time_offset_us;
  // A stroke ends when no camera has seen the pen for max_gap_us, or when only one has for longer than
  // a hand takes to pass in front of the other (max_bridge_us).
  if (s.down && (t - s.last_seen_t > static_cast<double>(options.max_gap_us) ||
                 t - s.last_sample_t > static_cast<double>(options.max_bridge_us)))
    end_stroke(s, out);
  // Keeps the pen followed through a frame without a stereo sample, from whichever camera still sees it.
  auto follow_one_camera = [&] {
    // Once both cameras have lost the pen for longer than a dropped report, a blob in one of them is no
    // evidence of it: a reflection near where the pen vanished fits one ray as well, and would hold a
    // lifted pen down until it is put down elsewhere, joining two strokes. Both cameras take it up again.
    if (!s.down || (s.lost_now && t - s.last_seen_t > static_cast<double>(options.short_gap_us))) return;
    // Nor, sooner, where the pen was resting when both lost it: it went out at a stroke's end, and a lamp its
    // blob had merged with in one camera shines on there as a new light.
    if (s.lost_now && s.filter.derivative.norm() < kRestingSpeed_m_s) return;
    const double gate = reach_m(t - s.last_seen_t, options.short_gap_us, s.filter.derivative.norm());
    const Candidates c0 = maybe_pen(s.cameras[0], k, s.last_seen_t, s.pen_px[0]);
    std::optional<Followed> x =
        follow_on_ray(rig.cam0, std::span<const Vec2>(c0.px.data(), size_t(c0.count)), s.pen_px[0], s.last_position, gate);
    int camera = 0;
    if (!x) {
      if (const auto j = frame_at_or_before(f1, t1)) {
        const Candidates c1 = maybe_pen(w1, *j, s.last_seen_t + s.time_offset_us, s.pen_px[1]);
        x = follow_on_ray(rig.cam1, std::span<const Vec2>(c1.px.data(), size_t(c1.count)), s.pen_px[1],
                          s.last_position, gate);
        camera = 1;
      }
    }
    if (!x) {
      s.lost_now = true;
      return;
    }
    s.both_lost += s.lost_now;
    s.lost_now = false;
    s.last_seen_t = t;
    s.last_position = x->position;
    s.pen_px[size_t(camera)] = x->px;
    ++s.counts.bridged_frames;
  };
  Interpolated ip;
  if (f0.blob_count[k] == 0 ||
      !tracking::interpolate_blobs(f1, w1.links, tracking::kMaxInterpolationGap * period_of(w1), t1, ip)) {
    follow_one_camera();
    return;
  }
  ++s.counts.frames_seen_by_both;
  // Epipolar lines run along the baseline, so a stray blob level with the LED in the other camera also
  // fits the geometry. While the pen is down and both cameras saw it last, a light beside it in either
  // camera is not paired: once the pen leaves one camera's view, that reflection fits the other camera's
  // pen centimetres deeper, and the stroke would end there. Of the rest, the fit nearest the pen's last
  // position wins, its epipolar misfit counted as distance (kMisfitDistance_m). A stroke only starts from a
  // frame where every fitting pair agrees.
  std::array<tracking::Triangulation, kIrSlots * kIrSlots> fits;
  std::array<std::array<int, 2>, kIrSlots * kIrSlots> fit_blobs;
  int fit_count = 0;
  const bool pen_pixels_current = s.down && s.last_seen_t == s.last_sample_t;
  std::array<bool, kIrSlots> beside0{}, beside1{};
  if (pen_pixels_current) {
    for (int i = 0; i < f0.blob_count[k]; ++i) beside0[size_t(i)] = beside_pen(s.cameras[0], k, i, s.last_seen_t, s.pen_px[0]);
    for (int j = 0; j < ip.count; ++j)
      beside1[size_t(j)] = beside_pen(w1, ip.frame, ip.source[size_t(j)], s.last_seen_t + s.time_offset_us, s.pen_px[1]);
  }
  int tried = 0;
  for (int i = 0; i < f0.blob_count[k]; ++i)
    for (int j = 0; j < ip.count; ++j) {
      if (beside0[size_t(i)] || beside1[size_t(j)]) continue;
      ++tried;
      const tracking::Triangulation tri =
          tracking::triangulate(rig.cam0, rig.cam1, f0.blobs[k][i], ip.px[j], options.method, options.max_reprojection_px);
      if (!tri.accepted) continue;
      fit_blobs[fit_count] = {i, j};
      fits[fit_count++] = tri;
    }
  if (fit_count == 0) {
    if (tried > 0) ++s.counts.rejected_reprojection;
    follow_one_camera();
    return;
  }
  int best = -1;
  if (s.down) {
    const double gate = reach_m(t - s.last_seen_t, options.short_gap_us, s.filter.derivative.norm());
    double best_cost = std::numeric_limits<double>::infinity();
    for (int c = 0; c < fit_count; ++c) {
      const double distance = (fits[c].X - s.last_position).norm();
      const double cost = std::hypot(distance, kMisfitDistance_m * fits[c].reprojection_error_px);
      if (distance <= gate && cost < best_cost) {
        best = c;
        best_cost = cost;
      }
    }
    // Seen again after a longer gap, but not where the pen could have got to: it was lifted and put down
    // elsewhere, so a new stroke starts here.
    if (best < 0 && t - s.last_seen_t > static_cast<double>(options.short_gap_us)) end_stroke(s, out);
    if (best < 0 && s.down) {
      ++s.counts.rejected_jump;
      return;
    }
  }
  if (!s.down) {
    // The best-fitting pair when every fitting pair agrees, else -1.
    auto agreed = [&] {
      int b = 0;
      for (int c = 1; c < fit_count; ++c) {
        if ((fits[c].X - fits[b].X).norm() > kJumpGate_m) return -1;
        if (fits[c].reprojection_error_px < fits[b].reprojection_error_px) b = c;
      }
      return b;
    };
    best = agreed();
    // The pen's LED lights up in both cameras at once, and a reflection level with it that shone before
    // (a lamp, a glint) did not: where the pairs disagree, those whose two blobs began to shine together are
    // the ones that may start a stroke.
    if (best < 0) {
      const double together_us = tracking::kMaxInterpolationGap * std::max(period_of(s.cameras[0]), period_of(w1));
      int kept = 0;
      for (int c = 0; c < fit_count; ++c) {
        const std::optional<double> since0 = lit_since(s.cameras[0], k, fit_blobs[c][0]);
        const std::optional<double> since1 = lit_since(w1, ip.frame, ip.source[size_t(fit_blobs[c][1])]);
        if (!since0 || !since1 || std::abs(*since0 - (*since1 - s.time_offset_us)) > together_us) continue;
        fits[kept] = fits[c];
        fit_blobs[kept++] = fit_blobs[c];
      }
      if (kept > 0) {
        fit_count = kept;
        best = agreed();
      }
    }
    // A light that appears in camera 1's later frame is not interpolated yet; the pen put down between
    // the two frames is one, and then the reflection level with it is all camera 1 offers, and fits
    // millimetres to centimetres off. Such a light that fits elsewhere makes the start wait for the next frame.
    if (best >= 0 && ip.frame + 1 < f1.size()) {
      const size_t later = ip.frame + 1;
      for (int b = 0; b < f1.blob_count[later] && best >= 0; ++b) {
        if (linked_from(w1, later, b) >= 0) continue;
        for (int i = 0; i < f0.blob_count[k] && best >= 0; ++i) {
          const tracking::Triangulation tri = tracking::triangulate(rig.cam0, rig.cam1, f0.blobs[k][i], f1.blobs[later][b],
                                                                    options.method, options.max_reprojection_px);
          if (tri.accepted && (tri.X - fits[best].X).norm() > kStartAgree_m) best = -1;
        }
      }
    }
    if (best < 0) {
      ++s.counts.ambiguous;
      return;
    }
    s.down = true;
    ++s.counts.strokes;
    s.filter = tracking::OneEuroState{};
  }
  const int64_t t_us = std::llround(t);
  const tracking::Triangulation& tri = fits[best];
  const std::optional<Vec3> smooth = tracking::one_euro_step(s.filter, options.filter, t_us, tri.X);
  if (!smooth) {
    ++s.counts.rejected_filter;
    return;
  }
  if (f0.blob_count[k] > 1 || ip.count > 1) ++s.stray_frames;
  if (!s.stroke_open) {
    out.push_back(pen_event(t_us, f0.line[k], EventKind::Down));
    s.stroke_open = true;
  }
  out.push_back(pen_event(t_us, f0.line[k], EventKind::Pen, *smooth));
  if (samples)
    samples->push_back({t_us, s.counts.strokes - 1, f0.t_us[k], f0.line[k], tri.X, *smooth,
                        tri.reprojection_error_px});
  s.both_lost += s.lost_now;
  s.lost_now = false;
  s.last_sample_t = t;
  s.last_sample_t_us = t_us;
  s.last_sample_line = f0.line[k];
  s.last_seen_t = t;
  s.last_position = tri.X;
  s.pen_px = {f0.blobs[k][fit_blobs[best][0]], ip.px[fit_blobs[best][1]]};
}

void trim(CameraWindow& w, uint64_t keep_from_index) {
  const CameraFrames& f = w.frames;
  if (f.size() == 0) return;
  size_t drop = 0;
  const double newest = f.t_frame_us.back();
  while (drop < f.size() && w.first_index + drop < keep_from_index &&
         newest - f.t_frame_us[drop] > static_cast<double>(kKeepUs))
    ++drop;
  if (drop >= kTrimChunk) erase_front(w, drop);
}

}  // namespace

bool TriangulateState::busy() const {
  return !cameras[0].waiting.empty() || !cameras[1].waiting.empty() || next_cam0 < cameras[0].end_index() || down;
}

void triangulate_report(const TrackingRig& rig, TriangulateState& s, const CameraReport& r) {
  CameraWindow& w = s.cameras[size_t(r.camera)];
  if (w.reports > 0 && r.t_us < w.last_arrival_us) {
    ++s.out_of_order;
    return;
  }
  const bool same_as_last = !w.waiting.empty()
                                ? w.waiting.back().blob_count == r.blob_count && w.waiting.back().blobs == r.blobs
                                : w.frames.size() > 0 && w.frames.blob_count.back() == r.blob_count &&
                                      w.frames.blobs.back() == r.blobs;
  // A report repeated at the same instant may be sent twice or held and sent with the next (a Bluetooth
  // burst, the pen at rest): the two cannot be told apart, and dropping one lost strokes in bursts.
  if (w.reports > 0 && r.t_us == w.last_arrival_us && same_as_last) ++s.duplicated;
  s.silent[size_t(r.camera)] = false;
  if (w.reports++ == 0) {
    w.origin_us = r.t_us;
  } else if (r.t_us > w.last_arrival_us) {
    w.gaps_us.push_back(static_cast<double>(r.t_us - w.last_arrival_us));
    if (w.gaps_us.size() > kPeriodGaps) w.gaps_us.pop_front();
    w.period_us = median_period(w.gaps_us);
  }
  w.last_arrival_us = r.t_us;
  w.waiting.push_back(r);
  while (w.waiting.size() > tracking::FrameNumbering::kLookahead) fix_oldest(w, r.camera, s, rig);
}

void triangulate_advance(int64_t now_us, const TrackingRig& rig, TriangulateState& s, std::vector<InputEvent>& out,
                         std::vector<PenSample>* samples) {
  const double now = static_cast<double>(now_us);
  for (int c = 0; c < 2; ++c) {
    CameraWindow& w = s.cameras[size_t(c)];
    if (w.reports > 0 && !s.silent[size_t(c)] && now_us - w.last_arrival_us > kSilenceUs) {
      s.silent[size_t(c)] = true;
      ++s.silences[size_t(c)];
    }
    // No report for a while: nothing more will renumber the waiting ones.
    if (!w.waiting.empty() && now - static_cast<double>(w.waiting.back().t_us) > kPendingTimeout * period_of(w))
      while (!w.waiting.empty()) fix_oldest(w, c, s, rig);
  }
  if (!s.time_offset_started) {
    s.time_offset_us = rig.time_offset_us;
    s.time_offset_started = true;
  }
  if (rig.estimate_time_offset && s.cam0_fixed >= kOffsetEvery * (s.offset_attempts + 1)) {
    const CameraWindow& w1 = s.cameras[1];
    const std::vector<tracking::MovingBlob> moving(s.moving.begin(), s.moving.end());
    const bool first = s.offset_estimates == 0;  // none observable yet: search the whole range
    ++s.offset_attempts;
    s.last_estimate = tracking::search_time_offset(moving, w1.frames, w1.links, tracking::kMaxInterpolationGap * period_of(w1),
                                                   rig.cam0, rig.cam1, first ? 0.0 : s.time_offset_us,
                                                   first ? kFirstSearchUs : kNextSearchUs);
    if (s.last_estimate.observable) {
      s.time_offset_us = s.last_estimate.offset_us;
      ++s.offset_estimates;
    }
  }
  CameraWindow& w0 = s.cameras[0];
  const CameraWindow& w1 = s.cameras[1];
  while (s.next_cam0 < w0.end_index()) {
    const size_t k = static_cast<size_t>(s.next_cam0 - w0.first_index);
    const double t1 = w0.frames.t_frame_us[k] + s.time_offset_us;
    const bool camera1_past = w1.frames.size() > 0 && w1.frames.t_frame_us.back() > t1;
    if (!camera1_past && now - t1 <= kCameraHorizonUs) break;
    track_frame(k, rig, s, out, samples);
    ++s.next_cam0;
  }
  // Camera 0 has gone silent with the pen down: the stroke ends by the same rules, a little later.
  const tracking::PenTrackOptions& o = rig.options;
  if (s.down && s.next_cam0 == w0.end_index() && w0.waiting.empty() &&
      (now - s.last_seen_t > static_cast<double>(o.max_gap_us) + 2 * kCameraHorizonUs ||
       now - s.last_sample_t > static_cast<double>(o.max_bridge_us) + 2 * kCameraHorizonUs))
    end_stroke(s, out);
  trim(w0, s.next_cam0 > 0 ? s.next_cam0 - 1 : 0);
  // Camera 1's window reaches back as far as camera 0's moving blobs and the next report to triangulate.
  trim(s.cameras[1], std::numeric_limits<uint64_t>::max());
}

std::vector<std::string> describe_device_problems(const TriangulateState& s) {
  std::vector<std::string> out;
  const tracking::ReportCounts& c = s.decoder.counts;
  auto say = [&](size_t n, const std::string& what) {
    if (n > 0) out.push_back(std::to_string(n) + " " + what);
  };
  say(c.garbled, "device report(s) garbled (not hexadecimal, or empty): skipped");
  say(c.bad_length, "device report(s) cut short for their report id: skipped (longer ones are read for their layout's bytes)");
  say(c.unknown_id, "device report(s) with an unknown report id: skipped");
  say(c.unknown_device, "report(s) from a device the log names as no camera: skipped");
  say(c.out_of_range_slots, "IR blob(s) outside the camera's 1024 x 768 pixels: dropped");
  say(c.bad_device_records, "device record(s) that do not read as D ADDRESS ROLE PRODUCT or name a product that is no Wii "
                            "Remote's (0306, 0330): their device's reports skipped");
  say(s.out_of_order, "report(s) stamped earlier than their remote's previous report (time going backwards): dropped");
  say(s.duplicated, "report(s) repeating their remote's previous report at the same instant (sent twice, or held "
                    "and sent with the next): kept");
  for (int k = 0; k < 2; ++k) {
    const CameraWindow& w = s.cameras[size_t(k)];
    // The median of recent arrival gaps: bursts and jitter leave it at a remote's 100 Hz.
    if (w.gaps_us.size() >= kMinPeriodGaps && (w.period_us < kNominalPeriodUs / kRateTolerance ||
                                               w.period_us > kNominalPeriodUs * kRateTolerance)) {
      out.push_back("camera " + std::to_string(k) + " reports at " + std::to_string(std::lround(1e6 / w.period_us)) +
                    " Hz, far from the 100 Hz of a Wii Remote streaming IR (a weak Bluetooth link, or not a remote): "
                    "its pen positions are less certain");
    }
  }
  for (int k = 0; k < 2; ++k)
    say(s.silences[size_t(k)], std::string("time(s) camera ") + char('0' + k) + " stopped reporting for more than 0.5 s" +
                                   (s.silent[size_t(k)] ? " (silent at the end)" : ""));
  say(s.both_lost, "time(s) neither camera saw the pen for a moment in the middle of a stroke (a hand over both): "
                  "the stroke went on where it was seen again");
  say(s.stray_frames, "pen sample(s) from frames that also showed another light (a reflection): the pen told apart by the other camera");
  say(s.counts.ambiguous, "frame(s) where two points fitted both cameras (a reflection in line with the pen): no stroke started");
  say(s.counts.rejected_jump, "frame(s) where the pen was seen farther than a hand moves it: not taken");
  say(s.counts.rejected_filter, "pen sample(s) not finite or not later than the one before: rejected");
  return out;
}

void triangulate_system(const FrameTime& frame, const TrackingRig& rig, const std::vector<InputEvent>& frame_events,
                        TriangulateState& state, std::vector<InputEvent>& pen_events, std::vector<PenSample>* samples) {
  pen_events.clear();
  for (const InputEvent& e : frame_events)
    if (const std::optional<CameraReport> r = state.decoder.read(e)) triangulate_report(rig, state, *r);
  triangulate_advance(frame.end_us, rig, state, pen_events, samples);
}

std::vector<InputEvent> track_log(std::span<const InputEvent> events, const TrackingRig& rig, tracking::PenTrack& track,
                                  TriangulateState* final_state) {
  TriangulateState state;
  std::vector<InputEvent> out, frame_events, pen_events;
  track.samples.clear();
  if (events.empty()) return out;
  FrameTime frame{0, events.front().t_us, events.front().t_us + kFrameStepUs};
  size_t next = 0;
  while (next < events.size() || state.busy()) {
    frame_events.clear();
    while (next < events.size() && events[next].t_us < frame.end_us) frame_events.push_back(events[next++]);
    triangulate_system(frame, rig, frame_events, state, pen_events, &track.samples);
    out.insert(out.end(), pen_events.begin(), pen_events.end());
    frame = {frame.index + 1, frame.end_us, frame.end_us + kFrameStepUs};
  }
  static_cast<tracking::PenCounts&>(track) = state.counts;
  if (final_state) *final_state = std::move(state);
  return out;
}

}  // namespace fire
