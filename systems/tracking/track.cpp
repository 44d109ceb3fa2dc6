#include "systems/tracking/track.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <map>
#include <sstream>
#include <cmath>
#include <limits>

namespace fire::tracking {
namespace {

constexpr double kMatchGatePx = 60.0;     // farthest a blob moves between two frames (about 2 m/s at 0.8 m)
constexpr double kEpipolarCapPx = 5.0;    // a blob farther than this from its epipolar line counts as this far

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

double frame_period_us(const CameraFrames& f) {
  std::vector<double> d;
  for (size_t k = 1; k < f.size(); ++k) d.push_back(f.t_frame_us[k] - f.t_frame_us[k - 1]);
  return median(std::move(d));
}

std::array<int8_t, kIrSlots> link_to_next(const CameraFrames& f, size_t k) {
  std::array<int8_t, kIrSlots> links;
  links.fill(-1);
  if (k + 1 >= f.size()) return links;
  const int na = f.blob_count[k], nb = f.blob_count[k + 1];
  auto nearest = [](const std::array<Vec2, kIrSlots>& from, int n, const Vec2& p, double& d1, double& d2) {
    int best = -1;
    d1 = d2 = std::numeric_limits<double>::infinity();
    for (int j = 0; j < n; ++j) {
      const double d = (from[j] - p).norm();
      if (d < d1) {
        d2 = d1;
        d1 = d;
        best = j;
      } else if (d < d2) {
        d2 = d;
      }
    }
    return best;
  };
  for (int i = 0; i < na; ++i) {
    double d1, d2, e1, e2;
    const int j = nearest(f.blobs[k + 1], nb, f.blobs[k][i], d1, d2);
    if (j < 0 || d1 > kMatchGatePx || !(d1 < 0.5 * d2)) continue;
    if (nearest(f.blobs[k], na, f.blobs[k + 1][j], e1, e2) != i || !(e1 < 0.5 * e2)) continue;
    links[i] = static_cast<int8_t>(j);
  }
  return links;
}

bool interpolate_blobs(const CameraFrames& f, const BlobLinks& links, double max_gap_us, double t, Interpolated& out) {
  out.count = 0;
  const auto it = std::upper_bound(f.t_frame_us.begin(), f.t_frame_us.end(), t);
  if (it == f.t_frame_us.begin() || it == f.t_frame_us.end()) return false;
  const size_t j = static_cast<size_t>(it - f.t_frame_us.begin()) - 1;
  const double t0 = f.t_frame_us[j], t1 = f.t_frame_us[j + 1];
  if (t1 - t0 > max_gap_us || j >= links.size()) return false;
  out.frame = j;
  out.s = (t - t0) / (t1 - t0);
  for (int i = 0; i < f.blob_count[j]; ++i) {
    const int8_t next = links[j][i];
    if (next < 0) continue;
    const Vec2& a = f.blobs[j][i];
    const Vec2& b = f.blobs[j + 1][next];
    out.px[out.count] = a + out.s * (b - a);
    out.source[out.count] = i;
    ++out.count;
  }
  return out.count > 0;
}

namespace {

BlobLinks link_all(const CameraFrames& f) {
  BlobLinks links(f.size());
  for (size_t k = 0; k < f.size(); ++k) links[k] = link_to_next(f, k);
  return links;
}

// A whole camera's frames with their links, for the batch (calibration) paths.
class Interpolator {
 public:
  explicit Interpolator(const CameraFrames& f)
      : f_(f), links_(link_all(f)), max_gap_us_(kMaxInterpolationGap * frame_period_us(f)) {}
  bool at(double t, Interpolated& out) const { return interpolate_blobs(f_, links_, max_gap_us_, t, out); }
  const BlobLinks& links() const { return links_; }
  double max_gap_us() const { return max_gap_us_; }

 private:
  const CameraFrames& f_;
  BlobLinks links_;
  double max_gap_us_;
};

Eigen::Matrix3d skew(const Vec3& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

// Sampson distance to x1^T E x0 = 0 in normalized coordinates.
double sampson(const Eigen::Matrix3d& E, const Vec2& n0, const Vec2& n1) {
  const Vec3 a = n0.homogeneous(), b = n1.homogeneous();
  const Vec3 Ea = E * a, Etb = E.transpose() * b;
  const double denom = Ea.head<2>().squaredNorm() + Etb.head<2>().squaredNorm();
  return denom > 0 ? std::abs(b.dot(Ea)) / std::sqrt(denom) : std::numeric_limits<double>::infinity();
}

}  // namespace

namespace {

constexpr int kPad = -2, kNoRole = -1;

// A Wii Remote's USB product id (vendor 057E): the original, and the Wii Remote Plus.
bool wii_remote_product(std::string product) {
  for (char& c : product) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return product == "0306" || product == "0330";
}

// A `meta device` record's device number and role (camera index, kPad, or kNoRole for a record that names
// a device but no role or product of a Wii Remote), or nothing when not even its device number reads.
std::optional<std::pair<int, int>> device_record(const std::string& text, std::string& address, bool& good) {
  std::istringstream in(text);
  long device = -1;
  std::string role, product;
  good = false;
  if (!(in >> device) || device < 0 || device > 1'000'000) return std::nullopt;
  if (!(in >> address >> role >> product) || !wii_remote_product(product)) return std::pair{int(device), kNoRole};
  good = true;
  if (role == "camera0") return std::pair{int(device), 0};
  if (role == "camera1") return std::pair{int(device), 1};
  if (role == "pad") return std::pair{int(device), kPad};
  good = false;
  return std::pair{int(device), kNoRole};
}

}  // namespace

void DeviceDecoder::save(SnapshotWriter& out) const {
  const ReportCounts& c = counts;
  for (size_t n : {c.ir_reports, c.not_ir, c.garbled, c.bad_length, c.unknown_id, c.unknown_device, c.pad_reports,
                   c.bad_device_records, c.out_of_range_slots})
    out.put(uint64_t(n));
  out.put(camera_address[0]);
  out.put(camera_address[1]);
  out.put(pad_address);
  out.put(uint64_t(role_of_.size()));
  for (const auto& [device, role] : role_of_) out.put(std::pair{int32_t(device), int32_t(role)});
  out.put(uint8_t(has_records_));
}

bool DeviceDecoder::load(SnapshotReader& in) {
  ReportCounts& c = counts;
  for (size_t* n : {&c.ir_reports, &c.not_ir, &c.garbled, &c.bad_length, &c.unknown_id, &c.unknown_device,
                    &c.pad_reports, &c.bad_device_records, &c.out_of_range_slots}) {
    uint64_t v = 0;
    in.get(v);
    *n = size_t(v);
  }
  in.get(camera_address[0]);
  in.get(camera_address[1]);
  in.get(pad_address);
  uint64_t roles = 0;
  in.get(roles);
  role_of_.clear();
  for (uint64_t k = 0; k < roles && in.ok(); ++k) {
    std::pair<int32_t, int32_t> entry;
    in.get(entry);
    if (entry.second != kPad && entry.second != kNoRole && entry.second != 0 && entry.second != 1) in.fail();
    role_of_[entry.first] = entry.second;
  }
  uint8_t records = 0;
  in.get(records);
  has_records_ = records != 0;
  return in.ok();
}

std::optional<CameraReport> DeviceDecoder::read(const InputEvent& e) {
  ReportCounts& c = counts;
  if (e.kind == EventKind::Meta && e.name == "device") {
    std::string address;
    bool good = false;
    const auto record = device_record(e.text, address, good);
    if (!good) ++c.bad_device_records;
    if (!record) return std::nullopt;
    has_records_ = true;
    const auto [device, role] = *record;
    // A device the log does not say is a Wii Remote with a role is no camera, whatever it was before.
    if (role == kNoRole) {
      role_of_[device] = kNoRole;
      return std::nullopt;
    }
    // A device number now taken by another role, or a role now held by another device, is given up.
    for (auto& [d, r] : role_of_)
      if (d != device && r == role) r = kNoRole;
    role_of_[device] = role;
    std::string& known = role >= 0 ? camera_address[size_t(role)] : pad_address;
    if (known.empty()) known = address;
    return std::nullopt;
  }
  if (e.kind != EventKind::Hid) return std::nullopt;
  if (!e.hid_ok) {
    ++c.garbled;
    return std::nullopt;
  }
  int camera = e.device == 0 || e.device == 1 ? e.device : kNoRole;
  if (has_records_) {
    const auto it = role_of_.find(e.device);
    camera = it == role_of_.end() ? kNoRole : it->second;
  }
  if (camera == kPad) {
    ++c.pad_reports;
    return std::nullopt;
  }
  if (camera == kNoRole) {
    ++c.unknown_device;
    return std::nullopt;
  }
  const DecodedReport r = decode_ir_report(e.bytes);
  switch (r.status) {
    case ReportStatus::Empty: ++c.garbled; return std::nullopt;
    case ReportStatus::NotIr: ++c.not_ir; return std::nullopt;
    case ReportStatus::BadLength: ++c.bad_length; return std::nullopt;
    case ReportStatus::UnknownId: ++c.unknown_id; return std::nullopt;
    case ReportStatus::Ok: break;
  }
  ++c.ir_reports;
  c.out_of_range_slots += static_cast<size_t>(r.out_of_range_slots);
  CameraReport out;
  out.camera = camera;
  out.t_us = e.t_us;
  out.line = e.line;
  out.blobs.fill(Vec2::Zero());
  for (const IrSlot& s : r.report.slots)
    if (s.seen) out.blobs[out.blob_count++] = Vec2(s.x, s.y);
  return out;
}

DeviceStreams decode_device_streams(std::span<const InputEvent> events) {
  DeviceStreams out;
  DeviceDecoder decoder;
  for (const InputEvent& e : events) {
    const std::optional<CameraReport> r = decoder.read(e);
    if (!r) continue;
    CameraFrames& f = out.cameras[size_t(r->camera)];
    f.t_us.push_back(r->t_us);
    f.line.push_back(r->line);
    f.t_frame_us.push_back(static_cast<double>(r->t_us));
    f.blob_count.push_back(r->blob_count);
    f.blobs.push_back(r->blobs);
  }
  out.camera_address = decoder.camera_address;
  out.pad_address = decoder.pad_address;
  out.counts = decoder.counts;
  return out;
}

namespace {

constexpr double kNominalPeriodUs = kReportPeriodUs;
constexpr double kRateReports = 200;         // settled reports after which their own rate replaces the nominal one
constexpr size_t kClockWindow = 400;         // trailing reports the line's position comes from (4 s)
constexpr int kMaxLostInARow = 3;
constexpr double kLostPenalty = 4.6;         // -log of a report's chance to be lost (about 1 %)
constexpr double kDefaultJitterUs = 1000, kMinJitterUs = 100;
constexpr size_t kJitterWindow = 101;
// Below this jitter (of a period) reports that arrive together were held back by a burst, the earlier ones
// delivered a period late or more; above it they may as well be a late report and the one it delayed.
constexpr double kBurstJitter = 0.25;
constexpr double kLateKnee = 3;  // jitters: beyond it a late report costs linearly, not quadratically

// The cost of a report `miss` jitters from the clock's line. Bluetooth holds reports back (a late one
// delays those behind it; a burst delivers a held report with the next) but never delivers one before
// its time, so lateness has a long tail and earliness none: Huber on the late side only. Without it a
// burst of held reports is cheaper to explain as a lost report, and the numbering stays one ahead.
double misfit_cost(double miss) { return miss <= kLateKnee ? 0.5 * miss * miss : kLateKnee * (miss - 0.5 * kLateKnee); }

// The jitter from reports' distances to the clock's line: their median, as a standard deviation.
double jitter_from(std::vector<double> misses) {
  std::nth_element(misses.begin(), misses.begin() + static_cast<std::ptrdiff_t>(misses.size() / 2), misses.end());
  return std::max(kMinJitterUs, 1.4826 * misses[misses.size() / 2]);
}

// The least-squares line through the (number, arrival) of reports lo..hi, leaving out those held back and
// delivered with the next (their arrival is the next one's), unless fewer than 2 are left. A NaN slope: the
// numbers do not spread.
FrameNumbering::Line fit_line(std::span<const double> arrivals, std::span<const uint8_t> held,
                              std::span<const double> number, size_t lo, size_t hi) {
  FrameNumbering::Line l;
  double count = 0;
  for (size_t i = lo; i <= hi; ++i) count += held[i] ? 0 : 1;
  // A window of reports all stamped alike (no real remote's) keeps them all.
  const bool skip_held = count >= 2;
  if (!skip_held) count = static_cast<double>(hi - lo + 1);
  for (size_t i = lo; i <= hi; ++i) {
    if (skip_held && held[i]) continue;
    l.mean_n += number[i];
    l.mean_t += arrivals[i];
  }
  l.mean_n /= count;
  l.mean_t /= count;
  double snn = 0, snt = 0;
  for (size_t i = lo; i <= hi; ++i) {
    if (skip_held && held[i]) continue;
    snn += (number[i] - l.mean_n) * (number[i] - l.mean_n);
    snt += (number[i] - l.mean_n) * (arrivals[i] - l.mean_t);
  }
  l.slope = snn > 0 ? snt / snn : std::numeric_limits<double>::quiet_NaN();
  return l;
}

// The whole log's frame numbers, from the causal ones (FrameNumbering). Where the arrival jitter spans more
// than a period, a few reports cannot tell a lost report from late ones, but every report after a loss
// arrives a period early against a numbering that missed it, and hundreds of them say so. So the numbers
// are chosen all at once: a Viterbi path over the count of frames lost so far, within kRenumberBand of the
// causal count, against one clock line through them all, refitted until the numbers stay.
constexpr int kRenumberBand = 24;
constexpr int kRenumberRounds = 8;

std::vector<double> renumber_whole_log(std::span<const double> arrivals, std::span<const uint8_t> held,
                                       std::vector<double> number) {
  const size_t n = arrivals.size();
  if (std::count(held.begin(), held.end(), uint8_t(0)) < 3) return number;
  constexpr int kStates = 2 * kRenumberBand + 1;
  std::vector<std::array<uint8_t, kStates>> from(n);  // per report and state: the best state of the report before
  for (int round = 0; round < kRenumberRounds; ++round) {
    const FrameNumbering::Line line = fit_line(arrivals, held, number, 0, n - 1);
    if (std::isnan(line.slope)) return number;
    std::vector<double> misses;
    for (size_t k = 0; k < n; ++k)
      if (!held[k]) misses.push_back(std::abs(arrivals[k] - line.at(number[k])));
    const double sigma = jitter_from(std::move(misses));
    // State j of report k: number centre(k) + j - kRenumberBand, about the numbers of the round before.
    auto centre = [&](size_t k) { return number[k]; };
    std::array<double, kStates> cost, next;
    cost.fill(std::numeric_limits<double>::infinity());
    cost[kRenumberBand] = 0;  // the first report is number 0 as it is
    for (size_t k = 1; k < n; ++k) {
      next.fill(std::numeric_limits<double>::infinity());
      for (int j = 0; j < kStates; ++j) {
        const double nk = centre(k) + j - kRenumberBand;
        const double emit = held[k] ? 0.0 : misfit_cost((arrivals[k] - line.at(nk)) / sigma);
        int best_from = -1;
        double best = std::numeric_limits<double>::infinity();
        // Report k - 1 in state i had number centre(k - 1) + i - kRenumberBand; the frames lost between are
        // nk minus that minus 1, from 0 to kMaxLostInARow (0 after a held report).
        const int shift = static_cast<int>(centre(k) - centre(k - 1)) - 1;
        const int max_lost = held[k - 1] ? 0 : kMaxLostInARow;
        for (int i = std::max(0, j + shift - max_lost); i <= std::min(kStates - 1, j + shift); ++i) {
          if (!std::isfinite(cost[size_t(i)])) continue;
          const double lost = j + shift - i;
          const double c = cost[size_t(i)] + kLostPenalty * lost;
          if (c < best) best = c, best_from = i;
        }
        if (best_from >= 0) next[size_t(j)] = best + emit;
        from[k][size_t(j)] = uint8_t(std::max(best_from, 0));
      }
      cost = next;
    }
    int j = static_cast<int>(std::min_element(cost.begin(), cost.end()) - cost.begin());
    std::vector<double> chosen(n);
    for (size_t k = n; k-- > 0;) {
      chosen[k] = centre(k) + j - kRenumberBand;
      if (k > 0) j = from[k][size_t(j)];
    }
    if (chosen == number) break;
    number = std::move(chosen);
  }
  return number;
}

}  // namespace

FrameNumbering::Line FrameNumbering::line() const {
  Line l;
  for (const auto& [n, t] : trailing) {
    l.mean_n += n;
    l.mean_t += t;
  }
  const double size = static_cast<double>(trailing.size());
  l.slope = count >= kRateReports && cnn > 0 ? cnt / cnn : kNominalPeriodUs;
  if (size > 0) {
    l.mean_n /= size;
    l.mean_t /= size;
  }
  return l;
}

double FrameNumbering::instant(double number) const { return line().at(number); }

double FrameNumbering::settle(std::span<const double> waiting, double previous_arrival) {
  const size_t m = std::min(waiting.size(), kLookahead + 1);
  // Reports delivered at one instant are consecutive frames (Bluetooth held the earlier ones back and
  // sent them with the last), and only the last one's arrival says when: the others' arrivals are late
  // by a period or more, not jitter.
  auto held = [&](size_t i) { return i + 1 < m && waiting[i] == waiting[i + 1]; };
  double number = 0;
  if (!trailing.empty()) {
    const double previous = trailing.back()[0];
    const double sigma =
        residuals.size() >= 16 ? jitter_from({residuals.begin(), residuals.end()}) : kDefaultJitterUs;
    const Line l = line();
    const double line0 = l.at(0), slope = l.at(1) - line0;
    const int max_skip = kMaxLostInARow * static_cast<int>(m) + 1;
    // cost[d]: the best cost of the reports so far with d frames skipped in all; from[i][d]: the d before.
    std::vector<double> cost(size_t(max_skip) + 1, std::numeric_limits<double>::infinity()), next(cost.size());
    std::vector<std::vector<int>> from(m, std::vector<int>(cost.size(), -1));
    cost[0] = 0;
    for (size_t i = 0; i < m; ++i) {
      std::fill(next.begin(), next.end(), std::numeric_limits<double>::infinity());
      const bool with_previous = i == 0 ? waiting[0] == previous_arrival : held(i - 1);
      for (int d = 0; d <= max_skip; ++d) {
        if (!std::isfinite(cost[size_t(d)])) continue;
        for (int step = 0; step <= (with_previous ? 0 : kMaxLostInARow) && d + step <= max_skip; ++step) {
          const double n = previous + static_cast<double>(i + 1) + d + step;
          const double miss = (waiting[i] - (line0 + slope * n)) / sigma;
          const double c = cost[size_t(d)] + (held(i) ? 0.0 : misfit_cost(miss)) + kLostPenalty * step;
          if (c < next[size_t(d + step)]) {
            next[size_t(d + step)] = c;
            from[i][size_t(d + step)] = d;
          }
        }
      }
      cost.swap(next);
    }
    int d = static_cast<int>(std::min_element(cost.begin(), cost.end()) - cost.begin());
    for (size_t i = m; i-- > 1;) d = from[i][size_t(d)];
    number = previous + 1 + d;
    // A held report's arrival would widen the jitter. It is the next report's, so where bursts are told
    // apart from late reports the line takes it a period earlier, near where it would have arrived: a fifth
    // of the reports arriving a period late pulled the line 2 ms late, unevenly.
    if (held(0)) return record(number, sigma < kBurstJitter * slope ? waiting[0] - slope : waiting[0]);
    residuals.push_back(std::abs(waiting[0] - (line0 + slope * number)));
    if (residuals.size() > kJitterWindow) residuals.pop_front();
  }
  return record(number, waiting[0]);
}

double FrameNumbering::record(double number, double arrival) {
  trailing.push_back({number, arrival});
  if (trailing.size() > kClockWindow) trailing.pop_front();
  count += 1;
  const double dn = number - mean_n, dt = arrival - mean_t;
  mean_n += dn / count;
  mean_t += dt / count;
  cnn += dn * (number - mean_n);
  cnt += dn * (arrival - mean_t);
  return number;
}

void fit_frame_clock(CameraFrames& f) {
  const size_t n = f.size();
  for (size_t k = 0; k < n; ++k) f.t_frame_us[k] = static_cast<double>(f.t_us[k]);
  if (n < 3) return;
  const double t_origin = static_cast<double>(f.t_us[0]);
  auto arrival = [&](size_t i) { return static_cast<double>(f.t_us[i]) - t_origin; };
  // Frame numbers as the live triangulation system settles them (FrameNumbering).
  std::vector<double> arrivals(n), number(n);
  for (size_t k = 0; k < n; ++k) arrivals[k] = arrival(k);
  FrameNumbering numbering;
  for (size_t k = 0; k < n; ++k)
    number[k] = numbering.settle(std::span<const double>(arrivals).subspan(k, std::min(n - k, FrameNumbering::kLookahead + 1)),
                                 k > 0 ? arrivals[k - 1] : std::numeric_limits<double>::quiet_NaN());
  std::vector<uint8_t> held(n, 0);
  for (size_t k = 0; k + 1 < n; ++k) held[k] = arrivals[k] == arrivals[k + 1];
  number = renumber_whole_log(arrivals, held, std::move(number));
  // Per report, the least-squares line t = a + b n through its neighbours on both sides, leaving out
  // the arrivals of reports held back and delivered with the next (FrameNumbering::settle).
  constexpr ptrdiff_t kHalfWindow = 200;  // +-2 s: long enough to average the jitter, short for slow drift
  for (ptrdiff_t k = 0; k < static_cast<ptrdiff_t>(n); ++k) {
    const auto lo = static_cast<size_t>(std::max<ptrdiff_t>(0, k - kHalfWindow));
    const auto hi = static_cast<size_t>(std::min<ptrdiff_t>(static_cast<ptrdiff_t>(n) - 1, k + kHalfWindow));
    FrameNumbering::Line line = fit_line(arrivals, held, number, lo, hi);
    if (std::isnan(line.slope)) line.slope = numbering.instant(1) - numbering.instant(0);
    const double t = t_origin + line.mean_t + line.slope * (number[size_t(k)] - line.mean_n);
    f.t_frame_us[size_t(k)] = k == 0 ? t : std::max(t, f.t_frame_us[size_t(k) - 1] + 1.0);
  }
}

size_t remove_static_blobs(CameraFrames& f, double radius_px, int min_frames) {
  const size_t n = f.size();
  auto has_blob_near = [&](size_t k, const Vec2& p) {
    for (int i = 0; i < f.blob_count[k]; ++i)
      if ((f.blobs[k][i] - p).norm() <= radius_px) return true;
    return false;
  };
  std::vector<std::array<bool, kIrSlots>> still(n);
  const auto need = static_cast<size_t>(std::max(2, min_frames));  // one frame proves nothing still
  for (size_t k = 0; k < n; ++k) {
    still[k].fill(false);
    for (int i = 0; i < f.blob_count[k]; ++i) {
      const Vec2 p = f.blobs[k][i];
      size_t run = 1;
      for (size_t j = k; j > 0 && run < need && has_blob_near(j - 1, p); --j) ++run;
      for (size_t j = k + 1; j < n && run < need && has_blob_near(j, p); ++j) ++run;
      still[k][i] = run >= need;
    }
  }
  size_t removed = 0;
  for (size_t k = 0; k < n; ++k) {
    uint8_t kept = 0;
    for (int i = 0; i < f.blob_count[k]; ++i) {
      if (still[k][i]) {
        ++removed;
        continue;
      }
      f.blobs[k][kept++] = f.blobs[k][i];
    }
    f.blob_count[k] = kept;
  }
  return removed;
}

TimeOffsetEstimate search_time_offset(std::span<const MovingBlob> moving, const CameraFrames& f1, const BlobLinks& links1,
                                      double max_gap1_us, const Camera& c0, const Camera& c1, double centre_us,
                                      double search_us) {
  TimeOffsetEstimate out;
  out.samples = moving.size();
  if (moving.size() < 30 || f1.size() < 3 || !(search_us > 0)) return out;
  const Eigen::Matrix3d R = c1.R * c0.R.transpose();
  const Vec3 t = c1.t - R * c0.t;
  const Eigen::Matrix3d E = skew(t) * R;
  const double focal = 0.25 * (c0.K.fx + c0.K.fy + c1.K.fx + c1.K.fy);
  auto cost = [&](double offset) {
    double sum = 0;
    Interpolated ip;
    for (const MovingBlob& s : moving) {
      double best = kEpipolarCapPx;
      if (interpolate_blobs(f1, links1, max_gap1_us, s.t_us + offset, ip))
        for (int j = 0; j < ip.count; ++j)
          best = std::min(best, focal * sampson(E, s.normalized, c1.undistort_normalized(ip.px[j])));
      sum += best;
    }
    return sum / static_cast<double>(moving.size());
  };
  constexpr double kStep = 1000.0;
  std::vector<double> grid;
  double best_offset = centre_us, best_cost = std::numeric_limits<double>::infinity();
  for (double d = -std::floor(search_us / kStep) * kStep; d <= search_us; d += kStep) {
    const double c = cost(centre_us + d);
    grid.push_back(c);
    if (c < best_cost) {
      best_cost = c;
      best_offset = centre_us + d;
    }
  }
  // Golden-section refinement within one grid step either side.
  const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = best_offset - kStep, b = best_offset + kStep;
  double x1 = b - phi * (b - a), x2 = a + phi * (b - a);
  double f1c = cost(x1), f2c = cost(x2);
  while (b - a > 1.0) {
    if (f1c < f2c) {
      b = x2;
      x2 = x1;
      f2c = f1c;
      x1 = b - phi * (b - a);
      f1c = cost(x1);
    } else {
      a = x1;
      x1 = x2;
      f1c = f2c;
      x2 = a + phi * (b - a);
      f2c = cost(x2);
    }
  }
  const double refined = 0.5 * (a + b);
  const double refined_cost = cost(refined);
  if (refined_cost < best_cost) {
    best_cost = refined_cost;
    best_offset = refined;
  }
  out.offset_us = best_offset;
  out.cost_px = best_cost;
  out.cost_at_zero_px = cost(0.0);
  out.observable = best_cost < 0.7 * median(grid);
  return out;
}

TimeOffsetEstimate estimate_time_offset(const DeviceStreams& streams, const Camera& c0, const Camera& c1,
                                        double search_us) {
  const CameraFrames& f0 = streams.cameras[0];
  const CameraFrames& f1 = streams.cameras[1];
  if (f0.size() < 3 || f1.size() < 3) return {};
  // Moving camera 0 blobs carry the timing; resting ones fit every offset alike.
  const Interpolator cam1(f1);
  const Interpolator cam0(f0);
  std::vector<MovingBlob> moving;
  for (size_t k = 0; k + 1 < f0.size(); ++k) {
    if (f0.t_frame_us[k + 1] - f0.t_frame_us[k] > cam0.max_gap_us()) continue;
    for (int i = 0; i < f0.blob_count[k]; ++i) {
      const int8_t next = cam0.links()[k][i];
      if (next < 0 || (f0.blobs[k + 1][next] - f0.blobs[k][i]).norm() < kMovingPx) continue;
      moving.push_back({f0.t_frame_us[k], c0.undistort_normalized(f0.blobs[k][i])});
    }
  }
  return search_time_offset(moving, f1, cam1.links(), cam1.max_gap_us(), c0, c1, 0.0, search_us);
}

WandExtraction extract_wand_observations(const DeviceStreams& streams, double cam1_offset_us) {
  WandExtraction out;
  const CameraFrames& f0 = streams.cameras[0];
  const CameraFrames& f1 = streams.cameras[1];
  out.frames = f0.size();
  if (f1.size() < 2) {
    for (size_t k = 0; k < f0.size(); ++k) (f0.blob_count[k] == 2 ? out.no_partner : out.not_two_blobs)++;
    return out;
  }
  const Interpolator cam1(f1);
  Interpolated ip;
  for (size_t k = 0; k < f0.size(); ++k) {
    if (f0.blob_count[k] != 2) {
      ++out.not_two_blobs;
      continue;
    }
    if (!cam1.at(f0.t_frame_us[k] + cam1_offset_us, ip) || ip.count != 2 || f1.blob_count[ip.frame] != 2 ||
        f1.blob_count[ip.frame + 1] != 2) {
      ++out.no_partner;
      continue;
    }
    WandObservation o;
    o.t_us = std::llround(f0.t_frame_us[k]);
    o.cam0 = {f0.blobs[k][0], f0.blobs[k][1]};
    o.cam1 = {ip.px[0], ip.px[1]};
    out.observations.push_back(o);
  }
  return out;
}

Result<WandCalibration> calibrate_wand_streams(DeviceStreams streams, const CalibrationOptions& options) {
  using R = Result<WandCalibration>;
  WandCalibration out;
  for (CameraFrames& f : streams.cameras) {
    fit_frame_clock(f);
    out.static_blobs_removed += remove_static_blobs(f);
  }
  // Calibrate with no offset, read the offset off the rig, calibrate again with it; the
  // rig improves with the offset and the offset with the rig, so repeat until it settles.
  constexpr int kMaxRounds = 4;
  constexpr double kSettled_us = 50.0;
  double offset = 0;
  for (int round = 1; round <= kMaxRounds; ++round) {
    out.extraction = extract_wand_observations(streams, offset);
    Result<CalibrationResult> rig = calibrate_wand(out.extraction.observations, options);
    if (!rig)
      return R::failure(rig.error() + " (" + std::to_string(out.extraction.observations.size()) + " of " +
                        std::to_string(out.extraction.frames) + " camera 0 frames gave wand observations)");
    out.rig = *rig;
    out.calibrations = round;
    out.time_offset_used_us = offset;
    out.rig.time_offset_us = offset;
    out.time_offset = estimate_time_offset(streams, rig->cam0, rig->cam1);
    if (!out.time_offset.observable || std::abs(out.time_offset.offset_us - offset) < kSettled_us) break;
    offset = out.time_offset.offset_us;
  }
  return out;
}

std::vector<InputEvent> pen_events(const PenTrack& track, const StrokeShaping& shaping) {
  std::vector<InputEvent> out;
  auto event = [](int64_t t, EventKind kind, const Vec3& p = Vec3::Zero()) {
    InputEvent e;
    e.t_us = t;
    e.kind = kind;
    e.p = p;
    return e;
  };
  size_t i = 0;
  while (i < track.samples.size()) {
    size_t end = i;
    while (end < track.samples.size() && track.samples[end].stroke == track.samples[i].stroke) ++end;
    TimedPolyline stroke;
    for (size_t k = i; k < end; ++k) {
      stroke.t_us.push_back(track.samples[k].t_us);
      stroke.points.push_back(track.samples[k].filtered);
    }
    if (shaping.simplify_tolerance > 0) {
      TimedPolyline kept;
      for (size_t k : rdp_simplify(stroke.points, shaping.simplify_tolerance)) {
        kept.t_us.push_back(stroke.t_us[k]);
        kept.points.push_back(stroke.points[k]);
      }
      stroke = std::move(kept);
    }
    if (shaping.resample_spacing > 0) stroke = resample_by_arc_length(stroke, shaping.resample_spacing);
    if (!stroke.points.empty()) {
      out.push_back(event(stroke.t_us.front(), EventKind::Down));
      for (size_t k = 0; k < stroke.points.size(); ++k) out.push_back(event(stroke.t_us[k], EventKind::Pen, stroke.points[k]));
      out.push_back(event(stroke.t_us.back(), EventKind::Up));
    }
    i = end;
  }
  return out;
}

}  // namespace fire::tracking
