// The triangulation system's state in a snapshot: every field, so that a session reopened from it
// triangulates the log's tail exactly as the run that wrote it did.
#include "systems/triangulate/triangulate.hpp"

namespace fire {

namespace {

using tracking::CameraReport;

void put(SnapshotWriter& out, const Vec2& p) {
  out.put(p.x());
  out.put(p.y());
}
bool get(SnapshotReader& in, Vec2& p) { return in.get(p.x()) && in.get(p.y()); }

void put(SnapshotWriter& out, const std::array<Vec2, kIrSlots>& blobs) {
  for (const Vec2& p : blobs) put(out, p);
}
bool get(SnapshotReader& in, std::array<Vec2, kIrSlots>& blobs) {
  for (Vec2& p : blobs)
    if (!get(in, p)) return false;
  return true;
}

// Counts are size_t in memory and u64 on disk, so a snapshot reads the same on any build.
template <class T>
void put_count(SnapshotWriter& out, T n) {
  out.put(uint64_t(n));
}
template <class T>
void get_count(SnapshotReader& in, T& n) {
  uint64_t v = 0;
  in.get(v);
  n = T(v);
}
void put_flag(SnapshotWriter& out, bool b) { out.put(uint8_t(b)); }
void get_flag(SnapshotReader& in, bool& b) {
  uint8_t v = 0;
  in.get(v);
  if (v > 1) in.fail();
  b = v != 0;
}

// A deque as a count and its elements, each written by `one`.
template <class T, class Put>
void put_deque(SnapshotWriter& out, const std::deque<T>& d, Put one) {
  put_count(out, d.size());
  for (const T& x : d) one(x);
}
template <class T, class Get>
void get_deque(SnapshotReader& in, std::deque<T>& d, Get one) {
  uint64_t n = 0;
  in.get(n);
  d.clear();
  for (uint64_t k = 0; k < n && in.ok(); ++k) one(d.emplace_back());
}

void put_report(SnapshotWriter& out, const CameraReport& r) {
  out.put(int32_t(r.camera));
  out.put(r.t_us);
  out.put(r.line);
  out.put(r.blob_count);
  put(out, r.blobs);
}
void get_report(SnapshotReader& in, CameraReport& r) {
  int32_t camera = 0;
  in.get(camera);
  in.get(r.t_us);
  in.get(r.line);
  in.get(r.blob_count);
  get(in, r.blobs);
  if ((camera != 0 && camera != 1) || r.blob_count > kIrSlots) in.fail();
  r.camera = camera;
}

void put_window(SnapshotWriter& out, const CameraWindow& c) {
  const tracking::CameraFrames& f = c.frames;
  out.put(f.t_us);
  out.put(f.line);
  out.put(f.t_frame_us);
  out.put(f.blob_count);
  put_count(out, f.blobs.size());
  for (const auto& blobs : f.blobs) put(out, blobs);
  put_count(out, c.links.size());
  for (const auto& link : c.links) out.put(link);
  out.put(c.first_index);
  put_deque(out, c.waiting, [&](const CameraReport& r) { put_report(out, r); });
  put_deque(out, c.gaps_us, [&](double g) { out.put(g); });
  out.put(c.period_us);
  out.put(c.origin_us);
  const tracking::FrameNumbering& n = c.clock;
  put_deque(out, n.trailing, [&](const std::array<double, 2>& t) { out.put(t); });
  for (double m : {n.count, n.mean_n, n.mean_t, n.cnn, n.cnt}) out.put(m);
  put_deque(out, n.residuals, [&](double r) { out.put(r); });
  out.put(c.last_arrival_us);
  out.put(c.reports);
}

void get_window(SnapshotReader& in, CameraWindow& c) {
  tracking::CameraFrames& f = c.frames;
  in.get(f.t_us);
  in.get(f.line);
  in.get(f.t_frame_us);
  in.get(f.blob_count);
  uint64_t n = 0;
  in.get(n);
  f.blobs.clear();
  for (uint64_t k = 0; k < n && in.ok(); ++k) get(in, f.blobs.emplace_back());
  const size_t frames = f.t_us.size();
  if (f.line.size() != frames || f.t_frame_us.size() != frames || f.blob_count.size() != frames || f.blobs.size() != frames)
    in.fail();
  for (uint8_t count : f.blob_count)
    if (count > kIrSlots) in.fail();
  in.get(n);
  c.links.clear();
  for (uint64_t k = 0; k < n && in.ok(); ++k) in.get(c.links.emplace_back());
  if (c.links.size() != frames) in.fail();
  in.get(c.first_index);
  get_deque(in, c.waiting, [&](CameraReport& r) { get_report(in, r); });
  get_deque(in, c.gaps_us, [&](double& g) { in.get(g); });
  in.get(c.period_us);
  in.get(c.origin_us);
  tracking::FrameNumbering& clock = c.clock;
  get_deque(in, clock.trailing, [&](std::array<double, 2>& t) { in.get(t); });
  for (double* m : {&clock.count, &clock.mean_n, &clock.mean_t, &clock.cnn, &clock.cnt}) in.get(*m);
  get_deque(in, clock.residuals, [&](double& r) { in.get(r); });
  in.get(c.last_arrival_us);
  in.get(c.reports);
}

}  // namespace

void save_triangulate_state(SnapshotWriter& out, const TriangulateState& s) {
  s.decoder.save(out);
  for (const CameraWindow& c : s.cameras) put_window(out, c);
  put_count(out, s.out_of_order);
  put_count(out, s.duplicated);
  put_count(out, s.both_lost);
  put_flag(out, s.lost_now);
  put_count(out, s.stray_frames);
  for (size_t n : s.silences) put_count(out, n);
  for (bool b : s.silent) put_flag(out, b);
  out.put(s.next_cam0);
  out.put(s.time_offset_us);
  put_flag(out, s.time_offset_started);
  put_deque(out, s.moving, [&](const tracking::MovingBlob& m) {
    out.put(m.t_us);
    put(out, m.normalized);
  });
  out.put(s.cam0_fixed);
  out.put(s.offset_attempts);
  out.put(int32_t(s.offset_estimates));
  const tracking::TimeOffsetEstimate& e = s.last_estimate;
  for (double v : {e.offset_us, e.cost_px, e.cost_at_zero_px}) out.put(v);
  put_count(out, e.samples);
  put_flag(out, e.observable);
  const tracking::PenCounts& p = s.counts;
  out.put(p.strokes);
  for (size_t n : {p.frames_seen_by_both, p.rejected_reprojection, p.rejected_jump, p.ambiguous, p.rejected_filter,
                   p.bridged_frames})
    put_count(out, n);
  put_flag(out, s.down);
  put_flag(out, s.stroke_open);
  put_flag(out, s.filter.primed);
  out.put(s.filter.t_us);
  out.put(s.filter.value);
  out.put(s.filter.derivative);
  out.put(s.last_sample_t);
  out.put(s.last_seen_t);
  out.put(s.last_sample_t_us);
  out.put(s.last_sample_line);
  out.put(s.last_position);
  for (const Vec2& px : s.pen_px) put(out, px);
}

bool load_triangulate_state(SnapshotReader& in, TriangulateState& s) {
  s = TriangulateState{};
  if (!s.decoder.load(in)) return false;
  for (CameraWindow& c : s.cameras) get_window(in, c);
  get_count(in, s.out_of_order);
  get_count(in, s.duplicated);
  get_count(in, s.both_lost);
  get_flag(in, s.lost_now);
  get_count(in, s.stray_frames);
  for (size_t& n : s.silences) get_count(in, n);
  for (bool& b : s.silent) get_flag(in, b);
  in.get(s.next_cam0);
  in.get(s.time_offset_us);
  get_flag(in, s.time_offset_started);
  get_deque(in, s.moving, [&](tracking::MovingBlob& m) {
    in.get(m.t_us);
    get(in, m.normalized);
  });
  in.get(s.cam0_fixed);
  in.get(s.offset_attempts);
  int32_t estimates = 0;
  in.get(estimates);
  s.offset_estimates = estimates;
  tracking::TimeOffsetEstimate& e = s.last_estimate;
  for (double* v : {&e.offset_us, &e.cost_px, &e.cost_at_zero_px}) in.get(*v);
  get_count(in, e.samples);
  get_flag(in, e.observable);
  tracking::PenCounts& p = s.counts;
  in.get(p.strokes);
  for (size_t* n : {&p.frames_seen_by_both, &p.rejected_reprojection, &p.rejected_jump, &p.ambiguous, &p.rejected_filter,
                    &p.bridged_frames})
    get_count(in, *n);
  get_flag(in, s.down);
  get_flag(in, s.stroke_open);
  get_flag(in, s.filter.primed);
  in.get(s.filter.t_us);
  in.get(s.filter.value);
  in.get(s.filter.derivative);
  in.get(s.last_sample_t);
  in.get(s.last_seen_t);
  in.get(s.last_sample_t_us);
  in.get(s.last_sample_line);
  in.get(s.last_position);
  for (Vec2& px : s.pen_px) get(in, px);
  // The windows index into each other: camera 0's next report to triangulate lies within its window.
  const CameraWindow& c0 = s.cameras[0];
  if (s.next_cam0 < c0.first_index || s.next_cam0 > c0.end_index()) in.fail();
  return in.ok();
}

}  // namespace fire
