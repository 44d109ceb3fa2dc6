#include "tools/app/app_window.hpp"

#include <algorithm>

namespace fire::app {

render::Box scene_box(const Mesh& mesh, const SurfaceLevels& surface, std::span<const Vec3> reference) {
  render::Box box;
  for (EdgeIndex e{0}; e < mesh.edge_slots(); ++e)
    if (mesh.edge_alive(e))
      for (const Vec3& p : mesh.polyline(e)) box.add(p);
  for (const Vec3& p : surface.positions) box.add(p);
  for (const Vec3& p : reference) box.add(p);
  return box;
}

Result<std::unique_ptr<AppWindow>> AppWindow::open(World& world, Scheduler& scheduler, uint32_t width, uint32_t height,
                                                   std::span<const Vec3> reference_positions,
                                                   std::span<const uint32_t> reference_triangles) {
  using R = Result<std::unique_ptr<AppWindow>>;
  std::unique_ptr<AppWindow> app(new AppWindow(world, scheduler));
  auto win = window::Window::create("FIRE", width, height);
  if (!win) return R::failure(win.error());
  app->window_ = std::move(*win);
  auto context = render::Context::create(app->window_->context_options());
  if (!context) return R::failure(context.error());
  app->context_ = std::move(*context);
  auto surface = app->window_->create_surface(app->context_->instance());
  if (!surface) return R::failure(surface.error());
  app->window_->framebuffer_size(app->width_, app->height_);
  auto presenter = render::Presenter::create(*app->context_, *surface, app->width_, app->height_);
  if (!presenter) return R::failure(presenter.error());
  app->presenter_ = std::move(*presenter);
  auto renderer =
      render::Renderer::create(*app->context_, {std::max(app->width_, 1u), std::max(app->height_, 1u), 0,
                                                app->presenter_->format(), true});
  if (!renderer) return R::failure(renderer.error());
  app->renderer_ = std::move(*renderer);
  if (Status s = app->renderer_->set_reference(reference_positions, reference_triangles); !s) return R::failure(s.error);
  auto hud = window::Hud::create(*app->context_, *app->presenter_, *app->window_);
  if (!hud) return R::failure(hud.error());
  app->hud_ = std::move(*hud);

  app->hud_data.wireframe_supported = app->context_->wireframe_supported();
  app->rejections_seen_ = world.rejections.size();
  if (!world.rejections.empty()) app->hud_data.last_rejection = world.rejections.back().reason;
  app->session_origin_us_ = world.frame.begin_us;
  app->wall_start_ = app->last_frame_ = WallClock::now();
  return app;
}

AppWindow::~AppWindow() { close(); }

size_t AppWindow::close() {
  // The HUD and the presenter use the context's device; the window outlives the surface the presenter owns.
  hud_.reset();
  presenter_.reset();
  renderer_.reset();
  const size_t messages = context_ ? context_->validation_message_count() : 0;
  context_.reset();
  window_.reset();
  return messages;
}

int64_t AppWindow::session_us() const {
  return session_origin_us_ +
         std::chrono::duration_cast<std::chrono::microseconds>(WallClock::now() - wall_start_).count();
}

void AppWindow::log_event(InputEvent e) {
  InputLog& log = world_.log;
  e.t_us = std::max({session_us(), world_.frame.begin_us, log.events.back().t_us});
  e.line = uint32_t(log.forgotten + log.events.size() + 2);  // its line in the recorded log (after the header)
  log.events.push_back(std::move(e));
}

void AppWindow::run_frame(bool last) {
  if (recorder_) recorder_->before_frame(world_);
  scheduler_.run_frame();
  if (recorder_) {
    recorder_->after_frame(world_, last);
    forget_delivered_events(world_);
  }
  begin_frame(world_, world_.frame.index + 1, world_.frame.end_us);
}

bool AppWindow::display(const render::Orbit& orbit, render::Image* capture) {
  World& w = world_;
  auto ms_since = [](WallClock::time_point& mark) {
    const auto now = WallClock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - mark).count();
    mark = now;
    return ms;
  };
  auto mark = WallClock::now();
  stages_ = {};
  const int64_t now_us = session_us();
  if (drive_frames_) drive_frames_();
  else
    while (w.frame.end_us <= now_us) run_frame();
  if (w.rejections.size() > rejections_seen_) {
    hud_data.last_rejection = w.rejections.back().reason;
    rejections_seen_ = w.rejections.size();
  }
  stages_.systems = ms_since(mark);
  window_->framebuffer_size(width_, height_);
  if (width_ == 0 || height_ == 0) return false;  // minimised: systems go on, nothing to show
  camera_ = render::orbit_camera(orbit, width_, height_);
  if (status_ = presenter_->wait(); !status_) return false;
  stages_.wait = ms_since(mark);
  if (status_ = renderer_->upload(w.mesh, w.surface); !status_) return false;
  const std::span<const Vec3> stroke = w.sketch.pen_down ? std::span<const Vec3>(w.sketch.stroke) : std::span<const Vec3>();
  if (status_ = renderer_->set_stroke(stroke); !status_) return false;
  if (status_ = renderer_->set_pen_feedback(w.mesh, w.pen_feedback); !status_) return false;
  if (status_ = renderer_->set_marks(marks_, next_mark_); !status_) return false;
  stages_.upload = ms_since(mark);
  const auto wall_now = WallClock::now();
  hud_data.frame_ms = std::chrono::duration<double, std::milli>(wall_now - last_frame_).count();
  last_frame_ = wall_now;
  hud_data.frames = scheduler_.frames();
  hud_data.timings = &scheduler_.timings();
  hud_data.frame_timing = &scheduler_.frame_timing();
  hud_data.vertices = w.mesh.vertex_count();
  hud_data.edges = w.mesh.edge_count();
  hud_data.faces = w.mesh.face_count();
  hud_data.points = w.mesh.live_point_count();
  hud_data.surface_quads = w.surface.quad_count();
  hud_data.border_mode = w.mesh.face_count() == 0 || w.mesh.border_in_progress();
  hud_data.border_loops = w.mesh.border_loop_count();
  hud_data.pending_bridges = w.mesh.pending_bridge_count();
  hud_data.pending_pieces = w.mesh.pending_piece_count();
  hud_->build(hud_data);
  stages_.hud = ms_since(mark);
  auto shown = presenter_->frame(*renderer_, camera_, hud_data.view, [&](VkCommandBuffer cmd) { hud_->draw(cmd); },
                                 capture);
  stages_.present = ms_since(mark);
  if (!shown) {
    status_ = Status::failure(shown.error());
    return false;
  }
  if (status_ = hud_->status(); !status_) return false;
  if (*shown == render::Presented::SwapchainStale) status_ = presenter_->resize(width_, height_);
  return *shown == render::Presented::Shown;
}

}  // namespace fire::app
