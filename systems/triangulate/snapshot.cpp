// The triangulation system's state in a snapshot: every field, so that a session reopened from it
// triangulates the log's tail exactly as the run that wrote it did: each struct's fields listed once
// (engine/snapshot_fields.hpp).
#include "engine/snapshot_fields.hpp"
#include "systems/triangulate/triangulate.hpp"

namespace fire {

namespace {

// Report and Window are the struct or the const struct, as Io writes or reads.
template <class Io, class Report>
void report_fields(Io& io, Report& r) {
  io.template as<int32_t>(r.camera);
  io(r.t_us);
  io(r.line);
  io(r.blob_count);
  io(r.blobs);
  io.check((r.camera == 0 || r.camera == 1) && r.blob_count <= kIrSlots);
}

template <class Io, class Window>
void window_fields(Io& io, Window& c) {
  auto& f = c.frames;
  io(f.t_us);
  io(f.line);
  io(f.t_frame_us);
  io(f.blob_count);
  io.sequence(f.blobs, [&](auto& blobs) { io(blobs); });
  const size_t frames = f.t_us.size();
  io.check(f.line.size() == frames && f.t_frame_us.size() == frames && f.blob_count.size() == frames && f.blobs.size() == frames);
  for (uint8_t count : f.blob_count) io.check(count <= kIrSlots);
  io.sequence(c.links, [&](auto& link) { io(link); });
  io.check(c.links.size() == frames);
  io(c.first_index);
  io.sequence(c.waiting, [&](auto& r) { report_fields(io, r); });
  io.sequence(c.gaps_us, [&](auto& g) { io(g); });
  io(c.period_us);
  io(c.origin_us);
  auto& n = c.clock;
  io.sequence(n.trailing, [&](auto& t) { io(t); });
  for (auto* m : {&n.count, &n.mean_n, &n.mean_t, &n.cnn, &n.cnt}) io(*m);
  io.sequence(n.residuals, [&](auto& r) { io(r); });
  io(c.last_arrival_us);
  io(c.reports);
}

template <class Io, class State>
void state_fields(Io& io, State& s) {
  io.object(s.decoder);
  for (auto& c : s.cameras) window_fields(io, c);
  io.count(s.out_of_order);
  io.count(s.duplicated);
  io.count(s.both_lost);
  io.flag(s.lost_now);
  io.count(s.stray_frames);
  for (auto& n : s.silences) io.count(n);
  for (auto& b : s.silent) io.flag(b);
  io(s.next_cam0);
  io(s.time_offset_us);
  io.flag(s.time_offset_started);
  io.sequence(s.moving, [&](auto& m) {
    io(m.t_us);
    io(m.normalized);
  });
  io(s.cam0_fixed);
  io(s.offset_attempts);
  io.template as<int32_t>(s.offset_estimates);
  auto& e = s.last_estimate;
  for (auto* v : {&e.offset_us, &e.cost_px, &e.cost_at_zero_px}) io(*v);
  io.count(e.samples);
  io.flag(e.observable);
  auto& p = s.counts;
  io(p.strokes);
  for (auto* n : {&p.frames_seen_by_both, &p.rejected_reprojection, &p.rejected_jump, &p.ambiguous, &p.rejected_filter,
                  &p.bridged_frames})
    io.count(*n);
  io.flag(s.down);
  io.flag(s.stroke_open);
  io.flag(s.filter.primed);
  io(s.filter.t_us);
  io(s.filter.value);
  io(s.filter.derivative);
  io(s.last_sample_t);
  io(s.last_seen_t);
  io(s.last_sample_t_us);
  io(s.last_sample_line);
  io(s.last_position);
  for (auto& px : s.pen_px) io(px);
  // The windows index into each other: camera 0's next report to triangulate lies within its window.
  io.check(s.next_cam0 >= s.cameras[0].first_index && s.next_cam0 <= s.cameras[0].end_index());
}

}  // namespace

void save_triangulate_state(SnapshotWriter& out, const TriangulateState& s) {
  SnapshotPut put{out};
  state_fields(put, s);
}

bool load_triangulate_state(SnapshotReader& in, TriangulateState& s) {
  s = TriangulateState{};
  SnapshotGet get{in};
  state_fields(get, s);
  return in.ok();
}

}  // namespace fire
