#pragma once
// The live app's window and its displayed frame, shared by `fire app` and perf/render's benchmark, so that
// the benchmark measures the frame a person sees.
//
// One displayed frame (display()): the session's systems for every fixed step the wall clock has passed,
// the renderer's uploads (changed ranges only), the stroke in progress and the pen's feedback, the HUD, the present (vsync).
#include <chrono>
#include <functional>
#include <memory>
#include <span>

#include "platform/render/present.hpp"
#include "platform/window/hud.hpp"
#include "platform/window/window.hpp"
#include "tools/app/session.hpp"
#include "tools/app/session_store.hpp"

namespace fire::app {

// What the view frames: the curves, the surface and the reference mesh.
render::Box scene_box(const Mesh& mesh, const SurfaceLevels& surface, std::span<const Vec3> reference);

// Wall time of the stages of one display(), in milliseconds.
struct FrameStages {
  double systems = 0;  // the fixed steps the wall clock has passed
  double wait = 0;     // the previous frame's commands (on lavapipe: its rasterization)
  double upload = 0;   // changed ranges of the pools and the surface, the stroke, the pen's feedback
  double hud = 0;      // the HUD's layout
  double present = 0;  // acquire, record, submit and present
};

class AppWindow {
 public:
  // A window of width x height pixels on `world`, whose frame has begun (as replay_headless leaves it): the
  // Vulkan context, the present path, the renderer with the reference mesh drawn see-through (no
  // triangles: none) and the HUD. The session's clock starts now, at the begun frame's log time.
  static Result<std::unique_ptr<AppWindow>> open(World& world, Scheduler& scheduler, uint32_t width, uint32_t height,
                                                 std::span<const Vec3> reference_positions,
                                                 std::span<const uint32_t> reference_triangles);
  ~AppWindow();
  AppWindow(const AppWindow&) = delete;
  AppWindow& operator=(const AppWindow&) = delete;

  // Log time now: the begun frame's, advanced by the wall clock since open().
  int64_t session_us() const;
  // Appends `e` to the input log at the session's time, never before the frame about to run nor before the
  // last event, so the log stays in time order and a replay delivers it in the same frame.
  void log_event(InputEvent e);
  // Runs the begun frame and begins the next; with a session recorder, writes the frame's events to the
  // session first and, after it, the snapshot the schedule asks for (one in any case after the `last`),
  // and drops the delivered events from memory (they are on disk).
  void run_frame(bool last = false);
  void record_into(SessionRecorder* recorder) { recorder_ = recorder; }
  // A live session runs the frames itself as the remotes' reports complete them (app_live.hpp): display()
  // then calls `step` instead of running the fixed steps the wall clock has passed.
  void drive_frames_with(std::function<void()> step) { drive_frames_ = std::move(step); }
  // The object's registration marks in the network's frame, the one at `next` highlighted; empty: none.
  void show_marks(std::vector<Vec3> marks, size_t next) {
    marks_ = std::move(marks);
    next_mark_ = next;
  }
  // One displayed frame, the camera from `orbit`. With `capture`, a presented frame is read back into it.
  // False: nothing was shown (minimised, the swapchain was remade for a new size, or status() failed).
  bool display(const render::Orbit& orbit, render::Image* capture = nullptr);

  // Destroys the Vulkan objects and the window; returns how many validation messages were reported.
  size_t close();

  const Status& status() const { return status_; }
  const FrameStages& stages() const { return stages_; }
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  // The view of the last displayed frame: what the cursor points at.
  const render::Camera& camera() const { return camera_; }
  window::Window& window() { return *window_; }
  window::Hud& hud() { return *hud_; }
  const render::Context& context() const { return *context_; }
  const render::Renderer& renderer() const { return *renderer_; }
  // What the HUD shows; display() fills in the frame's timings and counts.
  window::HudData hud_data;

 private:
  using WallClock = std::chrono::steady_clock;
  AppWindow(World& world, Scheduler& scheduler) : world_(world), scheduler_(scheduler) {}

  World& world_;
  Scheduler& scheduler_;
  SessionRecorder* recorder_ = nullptr;
  std::function<void()> drive_frames_;
  std::vector<Vec3> marks_;
  size_t next_mark_ = 0;
  std::unique_ptr<window::Window> window_;
  std::unique_ptr<render::Context> context_;
  std::unique_ptr<render::Presenter> presenter_;
  std::unique_ptr<render::Renderer> renderer_;
  std::unique_ptr<window::Hud> hud_;
  uint32_t width_ = 0, height_ = 0;
  render::Camera camera_;
  Status status_;
  FrameStages stages_;
  size_t rejections_seen_ = 0;
  WallClock::time_point wall_start_, last_frame_;
  int64_t session_origin_us_ = 0;
};

}  // namespace fire::app
