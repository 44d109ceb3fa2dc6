#pragma once
// A drawing session: the world's data and the per-frame system order of the design card, used by
// `fire replay` headless (and by the live app).
//
//   input -> triangulate -> register -> sketch -> split -> refine -> subdivide -> snap (the sync point: the snapping index)
//
// Each system is declared with the world data it reads and writes (names below), so the scheduler can
// refuse an order in which a system reads what a later one writes in the same frame.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "engine/input_log.hpp"
#include "engine/mesh.hpp"
#include "engine/scheduler.hpp"
#include "engine/snap_index.hpp"
#include "engine/surface.hpp"
#include "systems/input/input.hpp"
#include "systems/reconstruct/reconstruct.hpp"
#include "systems/register/register.hpp"
#include "systems/sketch/sketch.hpp"
#include "systems/split/edit.hpp"
#include "systems/triangulate/triangulate.hpp"

namespace fire {

struct World {
  // input
  InputLog log;
  InputCursor cursor;
  FrameTime frame;
  std::vector<InputEvent> frame_events;
  // triangulate: only with a rig (logs of device reports): the pen's events from the frame's reports
  std::optional<TrackingRig> rig;
  TriangulateState triangulate;
  std::vector<InputEvent> pen_events;
  // register: the pen's samples from the rig's frame to the object's (cmd mark, cmd register)
  RegistrationState registration;
  std::vector<InputEvent> object_events;  // the frame's pen events (object frame) and commands, for sketch
  // sketch
  SketchState sketch;
  SketchSettings sketch_settings;
  std::vector<EditRequest> requests;
  std::vector<Rejection> rejections;
  PenFeedback pen_feedback;  // for the renderer; outside world_hash
  // split
  Mesh mesh;
  SnapIndex snap;  // in step with `mesh` from the end of each frame
  EditHistory history;
  // refine, subdivide
  bool build_surface = true;
  reconstruct::Options surface_options;
  reconstruct::SurfaceBuild surface_build;
  SurfaceLevels surface;
};


// The design card's systems over `world`, in frame order, with their declared reads and writes.
std::vector<SystemSpec> session_systems(World& world);
// Builds the scheduler over session_systems(world), timed by `clock` (and by `cpu_clock` too, when given).
Scheduler make_scheduler(World& world, Scheduler::Clock clock, Scheduler::Clock cpu_clock = nullptr);
// Starts frame `index` covering [begin_us, begin_us + kFrameStepUs): the pools stamp what follows with it.
void begin_frame(World& world, uint64_t index, int64_t begin_us);
// Called before each frame runs (its events not delivered yet) and after it (before the next one begins,
// so the snapping index has synced with every write of the frame): the session writer's log appends and
// snapshots (tools/app/session_store.hpp).
struct ReplayHooks {
  std::function<void(World&)> before_frame;
  std::function<void(const World&)> after_frame;
};
// Gives the world the rig its device reports are triangulated with, and the sketch settings of a tracked
// pen (SketchSettings::vertex_snap, blend_reach): every path that runs a tracked drawing (fire replay
// --rig, a reopened session with a rig.json) runs it the same way.
void set_rig(World& world, const TrackingRig& rig);
// Whether a system still holds input or work that later frames will act on (the sketch system's requests,
// the triangulation system's reports or open stroke, a surface whose fit has not settled): a replay out of
// events runs frames until it does not.
bool systems_waiting(const World& world);
// Every event consumed and nothing waiting: where a replay ends.
bool replay_done(const World& world);
// Runs fixed-step frames from the first event until every event is consumed and no request waits.
void replay_headless(World& world, Scheduler& scheduler, const ReplayHooks& hooks = {});
// The same from where `world` stands: a frame begun, as replay_headless and a loaded snapshot leave it.
void continue_replay(World& world, Scheduler& scheduler, const ReplayHooks& hooks = {});
// The same for a live session, whose log holds every event stamped before `until_us` and none after: runs
// the frames that end by then, as continue_replay would run them on the finished log.
void run_frames_until(World& world, Scheduler& scheduler, int64_t until_us, const ReplayHooks& hooks = {});
// Drops the delivered events from the front of the world's log (all but the newest delivered one), so a
// live session's memory does not grow with its log; only for a log that is on disk elsewhere (a session
// folder's). Amortized: does nothing until `keep_below` events are waiting to be dropped.
void forget_delivered_events(World& world, size_t keep_below = 4096);
// Hash of the pools and the surface: what a replay must reproduce bit for bit.
uint64_t world_hash(const World& world);

}  // namespace fire
