#include "tools/app/session.hpp"

#include <cstdio>
#include <cstdlib>

#include "engine/hash.hpp"
#include "systems/refine/refine_system.hpp"
#include "systems/split/split_system.hpp"
#include "systems/subdivide/subdivide_system.hpp"

namespace fire {

std::vector<SystemSpec> session_systems(World& w) {
  using W = World;
  std::vector<SystemSpec> systems;
  systems.push_back(declare_system<Read<&W::log>, Read<&W::frame>, Write<&W::cursor>, Write<&W::frame_events>>(
      w, "input", [](const InputLog& log, const FrameTime& frame, InputCursor& cursor, std::vector<InputEvent>& events) {
        input_system(log, frame, cursor, events);
      }));
  systems.push_back(declare_system<Read<&W::frame>, Read<&W::rig>, Read<&W::frame_events>, Write<&W::triangulate>,
                                   Write<&W::pen_events>>(
      w, "triangulate",
      [](const FrameTime& frame, const std::optional<TrackingRig>& rig, const std::vector<InputEvent>& events,
         TriangulateState& state, std::vector<InputEvent>& pen_events) {
        if (rig) triangulate_system(frame, *rig, events, state, pen_events);
      }));
  systems.push_back(declare_system<Read<&W::frame_events>, Read<&W::pen_events>, Read<&W::rig>, Write<&W::registration>,
                                   Write<&W::object_events>, Write<&W::rejections>>(
      w, "register",
      [](const std::vector<InputEvent>& events, const std::vector<InputEvent>& pen_events,
         const std::optional<TrackingRig>& rig, RegistrationState& state, std::vector<InputEvent>& object_events,
         std::vector<Rejection>& rejections) {
        register_system(events, pen_events, rig.has_value(), state, object_events, rejections);
      }));
  systems.push_back(declare_system<Read<&W::object_events>, ReadPrevious<&W::mesh>, ReadPrevious<&W::snap>,
                                   Read<&W::sketch_settings>, Read<&W::log>, Read<&W::registration>, Write<&W::sketch>,
                                   Write<&W::requests>, Write<&W::rejections>, Write<&W::pen_feedback>>(
      w, "sketch",
      [](const std::vector<InputEvent>& events, const Mesh& mesh, const SnapIndex& snap, const SketchSettings& settings,
         const InputLog& log, const RegistrationState& registration, SketchState& state, std::vector<EditRequest>& requests,
         std::vector<Rejection>& rejections, PenFeedback& feedback) {
        // An older log replays by the rules it was drawn with.
        SketchSettings rules = settings;
        rules.topology_strokes = settings.topology_strokes && log.version >= 2;
        rules.middle_picks_face = settings.middle_picks_face && log.version >= 3;
        // Camera 0 sits at the rig's origin.
        const std::optional<Vec3> viewpoint =
            registration.transform ? std::optional<Vec3>(registration.transform->t) : std::nullopt;
        sketch_system(events, mesh, snap, rules, viewpoint, state, requests, rejections, feedback);
      }));
  systems.push_back(declare_system<Read<&W::requests>, Write<&W::mesh>, Write<&W::history>, Write<&W::rejections>>(
      w, "split", [](const std::vector<EditRequest>& requests, Mesh& mesh, EditHistory& history,
                     std::vector<Rejection>& rejections) { split_system(requests, mesh, history, rejections); }));
  systems.push_back(declare_system<Read<&W::build_surface>, Read<&W::mesh>, Read<&W::surface_options>,
                                   Write<&W::surface_build>>(
      w, "refine", [](const bool& build, const Mesh& mesh, const reconstruct::Options& options,
                      reconstruct::SurfaceBuild& surface_build) {
        if (build) refine_system(mesh, options, surface_build);
      }));
  systems.push_back(declare_system<Read<&W::build_surface>, Read<&W::surface_options>, Read<&W::frame>,
                                   Write<&W::surface_build>, Write<&W::surface>>(
      w, "subdivide", [](const bool& build, const reconstruct::Options& options, const FrameTime& frame,
                         reconstruct::SurfaceBuild& surface_build, SurfaceLevels& surface) {
        if (build) subdivide_system(options, frame, surface_build, surface);
      }));
  // The sync point: consumers of the frame's writes that later frames read.
  systems.push_back(declare_system<Read<&W::mesh>, Write<&W::snap>>(
      w, "snap", [](const Mesh& mesh, SnapIndex& snap) { snap.sync(mesh); }));
  return systems;
}

Scheduler make_scheduler(World& world, Scheduler::Clock clock, Scheduler::Clock cpu_clock) {
  auto scheduler = Scheduler::build(session_systems(world), clock, cpu_clock);
  // The order above is fixed in code: a refusal is a programming error, caught by every replay test.
  if (!scheduler) {
    std::fprintf(stderr, "internal error: %s\n", scheduler.error().c_str());
    std::abort();
  }
  return std::move(*scheduler);
}

void begin_frame(World& w, uint64_t index, int64_t begin_us) {
  w.frame = {index, begin_us, begin_us + kFrameStepUs};
  w.mesh.begin_frame(index);
}

void replay_headless(World& w, Scheduler& scheduler, const ReplayHooks& hooks) {
  if (w.log.events.empty()) return;
  begin_frame(w, 0, w.log.events.front().t_us);
  continue_replay(w, scheduler, hooks);
}

void set_rig(World& w, const TrackingRig& rig) {
  w.rig = rig;
  w.sketch_settings.vertex_snap = kTrackedVertexSnap;
  w.sketch_settings.blend_reach = kTrackedBlendReach;
}

// A provisional surface waits for its fit: running, or, in a session reopened from a snapshot taken
// meanwhile (the fit's progress is not in it), started over by the next frame's refine and subdivide from
// the same base mesh, which ends on the same settled surface. A refused network keeps its last surface,
// provisional or not, and waits for nothing.
bool systems_waiting(const World& w) {
  const bool surface_settling = w.build_surface && !w.surface.settled && w.surface_build.problem.empty();
  return !w.sketch.pending.empty() || (w.rig && w.triangulate.busy()) || surface_settling;
}

bool replay_done(const World& w) { return w.cursor.next >= w.log.events.size() && !systems_waiting(w); }

namespace {

// Skips the stretch with nothing to do before `t_us`, the next event's time: the frames still count, so
// frame numbers match a session that ran them all.
void skip_idle_frames(World& w, int64_t t_us) {
  if (systems_waiting(w) || t_us < w.frame.end_us) return;
  const int64_t steps = (t_us - w.frame.begin_us) / kFrameStepUs;
  begin_frame(w, w.frame.index + uint64_t(steps), w.frame.begin_us + steps * kFrameStepUs);
}

void run_one_frame(World& w, Scheduler& scheduler, const ReplayHooks& hooks) {
  if (hooks.before_frame) hooks.before_frame(w);
  scheduler.run_frame();
  if (hooks.after_frame) hooks.after_frame(w);
  begin_frame(w, w.frame.index + 1, w.frame.end_us);
}

}  // namespace

void continue_replay(World& w, Scheduler& scheduler, const ReplayHooks& hooks) {
  while (!replay_done(w)) {
    if (w.cursor.next < w.log.events.size()) skip_idle_frames(w, w.log.events[w.cursor.next].t_us);
    run_one_frame(w, scheduler, hooks);
  }
}

void run_frames_until(World& w, Scheduler& scheduler, int64_t until_us, const ReplayHooks& hooks) {
  for (;;) {
    // No event yet: the next one will come at until_us or later.
    skip_idle_frames(w, w.cursor.next < w.log.events.size() ? w.log.events[w.cursor.next].t_us : until_us);
    if (w.frame.end_us > until_us) return;
    run_one_frame(w, scheduler, hooks);
  }
}

void forget_delivered_events(World& w, size_t keep_below) {
  if (w.cursor.next <= keep_below) return;
  const size_t drop = w.cursor.next - 1;
  w.log.events.erase(w.log.events.begin(), w.log.events.begin() + std::ptrdiff_t(drop));
  w.cursor.next -= drop;
  w.log.forgotten += drop;
}

uint64_t world_hash(const World& w) {
  Fnv1a h;
  const uint64_t pools = w.mesh.hash(), surface = surface_hash(w.surface);
  h.mix(&pools, sizeof pools);
  h.mix(&surface, sizeof surface);
  return h.value;
}

}  // namespace fire
