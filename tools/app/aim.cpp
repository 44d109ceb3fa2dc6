#include "tools/app/aim.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>

namespace fire::app {

namespace {

// A light unseen this long has gone (the pen switched off, a lamp turned away); a slot missing from a report
// or two is no gap.
constexpr int64_t kTrackGapUs = 100'000;
// How far a light may move between two reports and still be the same light: a pen waved at 2 m/s 0.8 m from a
// camera crosses about 35 px in a report's 10 ms.
constexpr double kTrackGatePx = 120;
// Two cameras see one light come to rest (or light up at rest) within this of each other: the pen, which both
// see; a stray comes and goes on its own.
constexpr int64_t kSameRestUs = 250'000;

std::string at(const AimBlob& b) {
  char text[32];
  std::snprintf(text, sizeof text, "(%d, %d)", int(b.x), int(b.y));
  return text;
}

std::string seconds(int64_t us) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f s", double(us) * 1e-6);
  return text;
}

}  // namespace

AimMonitor::AimMonitor(int sensitivity) {
  for (Camera& c : cameras_) {
    c.view.sensitivity = sensitivity;
    c.view.trail.assign(size_t(kAimTrailColumns * kAimTrailRows), 0);
  }
}

void AimMonitor::battery(int camera, int percent, bool low) {
  AimCamera& v = cameras_[size_t(camera)].view;
  v.battery_percent = percent;
  v.battery_low = low;
}

void AimMonitor::follow(Camera& c, int64_t t_us, const IrSlots& slots) {
  std::erase_if(c.tracks, [&](const Track& k) { return t_us - k.last_us > kTrackGapUs; });
  // Each blob continues the nearest track within the gate, nearest pairs first; the others start tracks.
  std::vector<std::tuple<double, size_t, size_t>> pairs;  // distance, slot, track
  for (size_t s = 0; s < slots.size(); ++s)
    for (size_t k = 0; slots[s].seen && k < c.tracks.size(); ++k) {
      const double d = std::hypot(slots[s].x - c.tracks[k].x, slots[s].y - c.tracks[k].y);
      if (d < kTrackGatePx) pairs.emplace_back(d, s, k);
    }
  std::sort(pairs.begin(), pairs.end());
  std::array<bool, kIrSlots> slot_done{};
  std::vector<bool> track_done(c.tracks.size());
  for (const auto& [d, s, k] : pairs) {
    if (slot_done[s] || track_done[k]) continue;
    slot_done[s] = track_done[k] = true;
    Track& track = c.tracks[k];
    track.x = slots[s].x;
    track.y = slots[s].y;
    track.size = slots[s].size;
    track.last_us = t_us;
    if (std::hypot(track.x - track.rest_x, track.y - track.rest_y) > kAimStillPx) {
      track.rest_x = track.x;
      track.rest_y = track.y;
      track.still_since_us = t_us;
    }
  }
  for (size_t s = 0; s < slots.size(); ++s)
    if (slots[s].seen && !slot_done[s])
      c.tracks.push_back({.x = double(slots[s].x), .y = double(slots[s].y), .rest_x = double(slots[s].x),
                          .rest_y = double(slots[s].y), .still_since_us = t_us, .last_us = t_us, .size = slots[s].size});
}

void AimMonitor::classify(Camera& c, const Camera& other, int64_t t_us) {
  // The lights of both cameras' last reports paired one to one, the closest rests first: the pen comes to rest
  // (or lights up) at one instant in both, so a stray that came earlier stays unpaired even when the pen rests
  // beside it within kSameRestUs.
  const bool other_reports = other.last_us >= 0 && t_us - other.last_us <= kTrackGapUs;
  std::vector<std::tuple<int64_t, size_t, size_t>> pairs;  // rests apart, track here, track there
  for (size_t k = 0; k < c.tracks.size(); ++k)
    for (size_t m = 0; other_reports && c.tracks[k].last_us == t_us && m < other.tracks.size(); ++m) {
      const int64_t apart = std::abs(c.tracks[k].still_since_us - other.tracks[m].still_since_us);
      if (other.tracks[m].last_us == other.last_us && apart <= kSameRestUs) pairs.emplace_back(apart, k, m);
    }
  std::sort(pairs.begin(), pairs.end());
  std::vector<bool> paired_here(c.tracks.size()), paired_there(other.tracks.size());
  for (const auto& [apart, k, m] : pairs)
    if (!paired_here[k] && !paired_there[m]) paired_here[k] = paired_there[m] = true;

  for (size_t i = 0; i < c.tracks.size(); ++i) {
    Track& k = c.tracks[i];
    if (k.last_us != t_us) continue;
    const int64_t still = t_us - k.still_since_us;
    k.both = paired_here[i];
    k.stray = still >= (k.both ? kAimLampStillUs : kAimStrayStillUs);
    if (!k.stray) continue;
    const AimBlob seen{uint16_t(k.x), uint16_t(k.y), k.size, true};
    auto known = std::find_if(c.view.strays.begin(), c.view.strays.end(), [&](const AimBlob& s) {
      return std::hypot(s.x - k.rest_x, s.y - k.rest_y) <= 2 * kAimStillPx;
    });
    if (known == c.view.strays.end()) c.view.strays.push_back(seen);
    else *known = seen;
  }
}

bool AimMonitor::sees_pen(const Camera& c, int64_t t_us) {
  return c.pen_seen && c.last_us >= 0 && t_us - c.last_us <= kTrackGapUs;
}

void AimMonitor::report(int camera, int64_t t_us, const IrSlots& slots) {
  Camera& c = cameras_[size_t(camera)];
  c.view.reporting = true;
  if (c.first_us < 0) c.first_us = t_us;
  c.last_us = t_us;
  c.stamps.push_back(t_us);
  follow(c, t_us, slots);
  classify(c, cameras_[size_t(1 - camera)], t_us);
  c.view.blobs.clear();
  c.pen_seen = false;
  for (const Track& k : c.tracks) {
    if (k.last_us != t_us) continue;
    const AimBlob b{uint16_t(k.x), uint16_t(k.y), k.size, k.stray};
    c.view.blobs.push_back(b);
    if (k.stray) continue;
    c.pen_seen = true;
    ++c.view.trail[size_t(std::min(b.y / kAimTrailCellPx, kAimTrailRows - 1) * kAimTrailColumns +
                          std::min(b.x / kAimTrailCellPx, kAimTrailColumns - 1))];
  }
  for (int a = 0; a < 2; ++a) {
    std::optional<int64_t>& since = cameras_[size_t(a)].alone_since_us;
    if (!sees_pen(cameras_[size_t(a)], t_us) || sees_pen(cameras_[size_t(1 - a)], t_us)) since.reset();
    else if (!since) since = t_us;
  }
}

void AimMonitor::advance(int64_t now_us) {
  problems_.clear();
  for (int c = 0; c < 2; ++c) {
    Camera& k = cameras_[size_t(c)];
    const std::string name = "camera " + std::to_string(c), other = "camera " + std::to_string(1 - c);
    std::erase_if(k.stamps, [&](int64_t s) { return s <= now_us - kAimWindowUs; });
    k.view.rate_hz = int(k.stamps.size());
    const bool silent = k.last_us < 0 || now_us - k.last_us > kTrackGapUs;
    if (silent) k.view.blobs.clear();

    std::vector<AimBlob> strays;
    bool lamp = false;
    for (const AimBlob& b : k.view.blobs)
      if (b.stray) strays.push_back(b);
    for (const Track& t : k.tracks) lamp = lamp || (t.stray && t.both && t.last_us == k.last_us);
    if (!strays.empty()) {
      std::string where = at(strays[0]);
      for (size_t s = 1; s < strays.size(); ++s) where += (s + 1 == strays.size() ? " and " : ", ") + at(strays[s]);
      const std::string lights = strays.size() == 1 ? "a still light at " : "still lights at ";
      problems_.push_back(
          {AimProblemKind::StrayLight, c,
           lamp ? name + " sees " + lights + where + " that has not moved for " + seconds(kAimLampStillUs) + ", and " +
                      other + " sees it too: a lamp or a reflection (or the pen held still); switch it off or cover it"
                : name + " sees " + lights + where + " that " + other +
                      " does not: a stray light (a lamp, a window, a reflection); switch it off, cover it or turn " +
                      name + " away from it"});
    }
    if (k.alone_since_us && !silent && now_us - *k.alone_since_us >= kAimWindowUs)
      problems_.push_back({AimProblemKind::PenSeenByOne, c,
                           name + " sees the pen and " + other + " does not (for " + seconds(now_us - *k.alone_since_us) +
                               "): turn " + other + " toward the pen, or bring the pen where both see it"});
    if (k.first_us >= 0 && now_us - k.first_us >= kAimWindowUs && k.view.rate_hz < kAimMinRateHz)
      problems_.push_back({AimProblemKind::LowRate, c,
                           name + " sent " + std::to_string(k.view.rate_hz) + " IR reports in the last second, below " +
                               std::to_string(int(kAimMinRateHz)) +
                               ": bring it nearer the PC's Bluetooth adapter, away from Wi-Fi and USB 3 ports, or "
                               "put in fresh cells"});
    if (k.view.battery_low)
      problems_.push_back({AimProblemKind::LowBattery, c,
                           name + "'s battery is low (" + std::to_string(k.view.battery_percent.value_or(0)) +
                               " %): put in fresh cells before calibrating"});
  }
  for (const AimProblem& p : problems_)
    if (std::none_of(named_.begin(), named_.end(),
                     [&](const AimProblem& n) { return n.kind == p.kind && n.camera == p.camera; }))
      named_.push_back(p);
}

WorkingVolume working_volume(const tracking::Camera& cam0, const tracking::Camera& cam1) {
  // Where the optical axes pass closest; cameras that do not converge in front of them get a box 0.8 m ahead.
  constexpr double kFallbackDistanceM = 0.8;
  const Vec3 c0 = cam0.centre(), c1 = cam1.centre();
  const Vec3 d0 = cam0.R.row(2).transpose(), d1 = cam1.R.row(2).transpose();
  const Vec3 w = c0 - c1;
  const double b = d0.dot(d1), d = d0.dot(w), e = d1.dot(w), denom = 1 - b * b;
  WorkingVolume v;
  const double s = denom > 1e-9 ? (b * e - d) / denom : -1, u = denom > 1e-9 ? (e - b * d) / denom : -1;
  v.centre = s > 0 && u > 0 ? Vec3(0.5 * (c0 + s * d0 + c1 + u * d1))
                            : Vec3(0.5 * (c0 + c1) + kFallbackDistanceM * (d0 + d1).normalized());
  const Vec3 across = (c1 - c0).normalized();
  const Vec3 ahead = d0 + d1;
  const Vec3 deep = (ahead - ahead.dot(across) * across).normalized();
  v.axes.col(0) = across;
  v.axes.col(1) = deep.cross(across);
  v.axes.col(2) = deep;
  return v;
}

namespace {

// Whether `camera` images `X`: in front of it, within 45 degrees of its axis (so that the distortion's
// polynomial is not read where it folds back) and inside the sensor.
bool sees(const tracking::Camera& camera, const Vec3& X) {
  const Vec3 x = camera.R * X + camera.t;
  if (x.z() <= 0) return false;
  const tracking::Vec2 n(x.x() / x.z(), x.y() / x.z());
  if (std::abs(n.x()) > 1 || std::abs(n.y()) > 1) return false;
  const tracking::Vec2 p = tracking::distort_and_scale(camera.K, n);
  return p.x() >= 0 && p.x() < kWiimoteWidth && p.y() >= 0 && p.y() < kWiimoteHeight;
}

std::vector<VolumeCell> cells_of(const tracking::Camera& camera, const tracking::Camera& other, const WorkingVolume& v) {
  constexpr int kSamples = 24;  // points along a cell's ray inside the box
  std::vector<VolumeCell> out(size_t(kAimVolumeColumns * kAimVolumeRows), VolumeCell::Outside);
  const Vec3 centre = camera.centre();
  const Vec3 origin = v.axes.transpose() * (centre - v.centre);
  for (int row = 0; row < kAimVolumeRows; ++row)
    for (int col = 0; col < kAimVolumeColumns; ++col) {
      const Vec3 ray = camera.ray(tracking::Vec2((col + 0.5) * kAimVolumeCellPx, (row + 0.5) * kAimVolumeCellPx));
      const Vec3 dir = v.axes.transpose() * ray;
      double near = 0, far = 1e9;
      for (int k = 0; k < 3; ++k) {
        if (std::abs(dir(k)) < 1e-12) {
          if (std::abs(origin(k)) > v.half(k)) far = -1;
          continue;
        }
        const double a = (-v.half(k) - origin(k)) / dir(k), b = (v.half(k) - origin(k)) / dir(k);
        near = std::max(near, std::min(a, b));
        far = std::min(far, std::max(a, b));
      }
      if (near >= far) continue;
      VolumeCell& cell = out[size_t(row * kAimVolumeColumns + col)];
      cell = VolumeCell::ThisCameraOnly;
      for (int s = 0; s < kSamples && cell != VolumeCell::BothCameras; ++s)
        if (sees(other, centre + (near + (s + 0.5) / kSamples * (far - near)) * ray)) cell = VolumeCell::BothCameras;
    }
  return out;
}

}  // namespace

std::array<std::vector<VolumeCell>, 2> volume_cells(const tracking::Camera& cam0, const tracking::Camera& cam1) {
  const WorkingVolume v = working_volume(cam0, cam1);
  return {cells_of(cam0, cam1, v), cells_of(cam1, cam0, v)};
}

double overlap_share(std::span<const VolumeCell> cells) {
  if (cells.empty()) return 0;
  return double(std::count(cells.begin(), cells.end(), VolumeCell::BothCameras)) / double(cells.size());
}

namespace {

constexpr int kPictureScale = 2;  // sensor pixels per picture pixel

void fill(render::Image& im, int x0, int y0, int x1, int y1, const uint8_t (&rgb)[3]) {
  for (int y = std::max(y0, 0); y < std::min(y1, int(im.height)); ++y)
    for (int x = std::max(x0, 0); x < std::min(x1, int(im.width)); ++x)
      std::copy(rgb, rgb + 3, &im.rgba[(size_t(y) * im.width + size_t(x)) * 4]);
}

void disc(render::Image& im, const AimBlob& b, const uint8_t (&rgb)[3]) {
  const double cx = (b.x + 0.5) / kPictureScale, cy = (b.y + 0.5) / kPictureScale;
  const double r = aim_blob_radius_px(b.size) / kPictureScale;
  for (int y = int(std::floor(cy - r)); y <= int(std::ceil(cy + r)); ++y)
    for (int x = int(std::floor(cx - r)); x <= int(std::ceil(cx + r)); ++x)
      if (std::hypot(x + 0.5 - cx, y + 0.5 - cy) <= r) fill(im, x, y, x + 1, y + 1, rgb);
}

}  // namespace

render::Image aim_picture(const AimCamera& camera, std::span<const VolumeCell> volume) {
  render::Image im;
  im.width = kWiimoteWidth / kPictureScale;
  im.height = kWiimoteHeight / kPictureScale;
  im.rgba.assign(size_t(im.width) * im.height * 4, 255);
  fill(im, 0, 0, int(im.width), int(im.height), AimColour::background);
  constexpr int kVolumeCell = kAimVolumeCellPx / kPictureScale, kTrailCell = kAimTrailCellPx / kPictureScale;
  for (size_t k = 0; k < volume.size(); ++k) {
    if (volume[k] == VolumeCell::Outside) continue;
    const int x = int(k % kAimVolumeColumns) * kVolumeCell, y = int(k / kAimVolumeColumns) * kVolumeCell;
    fill(im, x, y, x + kVolumeCell, y + kVolumeCell,
         volume[k] == VolumeCell::BothCameras ? AimColour::both : AimColour::this_only);
  }
  for (size_t k = 0; k < camera.trail.size(); ++k) {
    if (camera.trail[k] == 0) continue;
    const int x = int(k % kAimTrailColumns) * kTrailCell, y = int(k / kAimTrailColumns) * kTrailCell;
    fill(im, x, y, x + kTrailCell, y + kTrailCell, AimColour::trail);
  }
  for (const AimBlob& s : camera.strays) disc(im, s, AimColour::stray);
  for (const AimBlob& b : camera.blobs) disc(im, b, b.stray ? AimColour::stray : AimColour::pen);
  return im;
}

}  // namespace fire::app
