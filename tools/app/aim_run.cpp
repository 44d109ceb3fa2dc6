#include "tools/app/aim_run.hpp"

#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "platform/clock.hpp"
#include "platform/files.hpp"
#include "platform/wiimote/driver.hpp"
#include "platform/wiimote/hidapi_backend.hpp"
#include "platform/wiimote/roles.hpp"
#include "systems/tracking/rig_io.hpp"
#include "tools/app/aim.hpp"
#include "tools/app/app_script.hpp"
#include "tools/app/app_window.hpp"
#include "tools/app/fake_rig.hpp"

namespace fire::app {

namespace {

int fail(const std::string& message) {
  std::cerr << "fire aim: " << message << "\n";
  return 1;
}

// The camera remotes through the driver, their reports handed to an AimMonitor as the log writer stamps them.
class AimRemotes {
 public:
  static Result<std::unique_ptr<AimRemotes>> open(const AimOptions& o, std::vector<wiimote::RemoteAssignment> assigned) {
    using R = Result<std::unique_ptr<AimRemotes>>;
    std::unique_ptr<AimRemotes> r(new AimRemotes);
    wiimote::Backend* backend = nullptr;
    wiimote::Clock clock = wiimote::system_clock();
    if (o.fake_rig_seed) {
      auto fake = FakeDrawingRig::create(*o.fake_rig_seed, 0);
      if (!fake) return R::failure(fake.error());
      r->fake_ = std::move(*fake);
      backend = &r->fake_->remotes().backend();
      clock = r->fake_->remotes().clock();
    } else {
      r->hardware_ = std::make_unique<wiimote::HidapiBackend>();
      backend = r->hardware_.get();
    }
    r->log_ = std::make_unique<wiimote::LogWriter>(clock);
    wiimote::DriverOptions options;
    options.startup.sensitivity = o.ir_sensitivity;
    r->driver_ = std::make_unique<wiimote::Driver>(*backend, *r->log_, std::move(assigned), options, clock);
    auto scan = r->driver_->open_all();
    if (!scan) return R::failure(scan.error());
    if (const int cameras = r->driver_->cameras(); cameras < 2) {
      std::string why = "needs two Wii Remotes as cameras and found " + std::to_string(cameras);
      for (const std::string& e : scan->open_errors) why += "\n  " + e;
      return R::failure(why + "\n  (fire devices lists what this machine sees)");
    }
    for (const std::string& e : scan->open_errors) std::cerr << "fire aim: " << e << "\n";
    if (!r->fake_) r->driver_->start();  // the fake remotes are read on this thread as their clock moves
    return r;
  }
  ~AimRemotes() { driver_->stop(); }

  // Moves on by `ns` (the fake rig's clock, a millisecond at a time; real remotes: sleeping, none for 0), hands
  // `monitor` every report stamped meanwhile and calls `each` with the log's time after each batch.
  void run_for(int64_t ns, AimMonitor& monitor, const std::function<void(int64_t)>& each) {
    auto feed = [&] {
      std::vector<InputEvent> taken;
      const int64_t now = log_->now_us();
      log_->take_before(now, taken);
      for (const InputEvent& e : taken) {
        if (e.kind != EventKind::Hid || e.device < 0 || e.device > 1) continue;
        const DecodedReport d = decode_ir_report(e.bytes);
        if (d.status == ReportStatus::Ok) monitor.report(e.device, e.t_us, d.report.slots);
      }
      for (const wiimote::RemoteView& v : driver_->remotes())
        if (wiimote::is_camera(v.role) && v.status)
          monitor.battery(v.device, wiimote::battery_percent(*v.status), v.status->battery_low());
      // No pen is drawn while aiming: the driver's pen notices would be about the lamp or the wand.
      for (const wiimote::Notice& n : driver_->take_notices())
        if (n.device != wiimote::kPenNotice) std::cerr << "fire aim: " << wiimote::describe(n) << "\n";
      monitor.advance(now);
      if (origin_us_ < 0 && driver_->cameras(wiimote::LinkState::Running) == 2) origin_us_ = now;
      each(now);
    };
    if (fake_) {
      fake_->remotes().advance(ns, *driver_, feed);
      return;
    }
    const int64_t end = log_->now_us() + ns / 1000;
    do {
      if (ns > 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
      feed();
    } while (log_->now_us() < end);
  }
  std::vector<wiimote::RemoteView> remotes() const { return driver_->remotes(); }
  // The log's time when both cameras first ran; -1 before.
  int64_t origin_us() const { return origin_us_; }

 private:
  AimRemotes() = default;
  std::unique_ptr<FakeDrawingRig> fake_;
  std::unique_ptr<wiimote::Backend> hardware_;
  std::unique_ptr<wiimote::LogWriter> log_;
  std::unique_ptr<wiimote::Driver> driver_;
  int64_t origin_us_ = -1;
};

nlohmann::ordered_json blobs_json(const std::vector<AimBlob>& blobs) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const AimBlob& b : blobs) out.push_back({{"x", b.x}, {"y", b.y}, {"size", b.size}, {"stray", b.stray}});
  return out;
}

// Each camera's state, with its remote's address and link state when the driver has it.
nlohmann::ordered_json cameras_json(const AimMonitor& monitor, const std::vector<wiimote::RemoteView>& remotes,
                                    bool with_strays) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (int c = 0; c < 2; ++c) {
    const AimCamera& k = monitor.camera(c);
    nlohmann::ordered_json j;
    j["camera"] = c;
    for (const wiimote::RemoteView& v : remotes)
      if (wiimote::is_camera(v.role) && v.device == c) {
        j["remote"] = v.address;
        j["state"] = std::string(wiimote::link_state_name(v.state));
      }
    j["rate_hz"] = k.rate_hz;
    j["battery_percent"] = k.battery_percent ? nlohmann::ordered_json(*k.battery_percent) : nlohmann::ordered_json();
    j["battery_low"] = k.battery_low;
    j["sensitivity"] = k.sensitivity;
    j["blobs"] = blobs_json(k.blobs);
    if (with_strays) j["strays"] = blobs_json(k.strays);
    out.push_back(std::move(j));
  }
  return out;
}

std::vector<std::string> texts(const std::vector<AimProblem>& problems) {
  std::vector<std::string> out;
  for (const AimProblem& p : problems) out.push_back(p.text);
  return out;
}

// Prints a JSON line at every whole second since both cameras ran.
class SecondLines {
 public:
  void at(int64_t now_us, const AimRemotes& remotes, const AimMonitor& monitor) {
    if (remotes.origin_us() < 0 || now_us - remotes.origin_us() < next_s_ * 1'000'000) return;
    nlohmann::ordered_json line;
    line["t_s"] = next_s_++;
    line["cameras"] = cameras_json(monitor, remotes.remotes(), false);
    line["problems"] = texts(monitor.problems());
    std::cout << line.dump() << std::endl;
  }

 private:
  int64_t next_s_ = 1;
};

// The line at the end: every problem named, every stray seen, the share of each image both cameras see the
// working volume in (null without a rig), the pictures written.
void print_summary(int64_t now_us, const AimRemotes& remotes, const AimMonitor& monitor,
                   const std::array<std::vector<VolumeCell>, 2>* volume, const std::vector<std::string>& pictures) {
  nlohmann::ordered_json out;
  out["t_s"] = remotes.origin_us() < 0 ? 0.0 : double(now_us - remotes.origin_us()) * 1e-6;
  out["cameras"] = cameras_json(monitor, remotes.remotes(), true);
  out["problems_named"] = texts(monitor.named());
  out["overlap"] = volume ? nlohmann::ordered_json{overlap_share((*volume)[0]), overlap_share((*volume)[1])}
                          : nlohmann::ordered_json();
  out["pictures"] = pictures;
  std::cout << out.dump() << std::endl;
}

constexpr const char* kNoRig =
    "where the two views overlap on the working volume needs a rig: give --rig RIG.json once fire calibrate has made one";

// Headless: the remotes watched for `seconds` from when both cameras run, then one picture per camera.
int run_headless(const AimOptions& o, AimRemotes& remotes, AimMonitor& monitor,
                 const std::array<std::vector<VolumeCell>, 2>* volume) {
  // Real remotes that never both start would keep the command waiting: they get this long.
  constexpr int64_t kStartUs = 10'000'000;
  SecondLines lines;
  int64_t now_us = 0, waited_us = 0;
  while (remotes.origin_us() < 0 || now_us - remotes.origin_us() < int64_t(o.seconds * 1e6)) {
    remotes.run_for(10'000'000, monitor, [&](int64_t now) {
      now_us = now;
      lines.at(now, remotes, monitor);
    });
    waited_us += 10'000;
    if (remotes.origin_us() < 0 && waited_us > kStartUs) {
      std::string states;
      for (const wiimote::RemoteView& v : remotes.remotes()) states += "\n  " + wiimote::describe(v);
      return fail("the two cameras did not both start within " + std::to_string(kStartUs / 1'000'000) + " s:" + states);
    }
  }
  std::vector<std::string> pictures;
  for (int c = 0; c < 2; ++c) {
    const std::string path = (std::filesystem::path(o.png_dir) / ("camera" + std::to_string(c) + ".png")).string();
    const render::Image im = aim_picture(monitor.camera(c), volume ? std::span<const VolumeCell>((*volume)[size_t(c)])
                                                                   : std::span<const VolumeCell>());
    if (Status s = render::write_png(im, path); !s) return fail("--png-dir: " + s.error);
    pictures.push_back(path);
  }
  if (!volume) std::cerr << "fire aim: " << kNoRig << "\n";
  print_summary(now_us, remotes, monitor, volume, pictures);
  return 0;
}

// What the window's HUD shows of the monitor.
void fill_hud(window::HudData& hud, const AimRemotes& remotes, const AimMonitor& monitor,
              const std::array<std::vector<VolumeCell>, 2>* volume) {
  hud.live.clear();
  for (const wiimote::RemoteView& v : remotes.remotes()) hud.live.push_back(wiimote::describe(v));
  if (!volume) hud.live.push_back(kNoRig);
  hud.live.push_back("Esc quits");
  hud.problems = texts(monitor.problems());
  for (int c = 0; c < 2; ++c) {
    const AimCamera& k = monitor.camera(c);
    window::CameraView& view = hud.cameras[size_t(c)];
    view.present = k.reporting;
    view.pen_seen = false;
    view.blobs.clear();
    for (const AimBlob& b : k.blobs) {
      view.blobs.push_back({float(b.x), float(b.y), b.size, b.stray});
      view.pen_seen = view.pen_seen || !b.stray;
    }
    view.strays.clear();
    for (const AimBlob& b : k.strays) view.strays.push_back({float(b.x), float(b.y), b.size, true});
    view.lines = {std::to_string(k.rate_hz) + " IR reports/s, battery " +
                      (k.battery_percent ? std::to_string(*k.battery_percent) + "%" : std::string("?")) +
                      ", sensitivity " + std::to_string(k.sensitivity)};
    if (volume) {
      view.volume.assign((*volume)[size_t(c)].size(), 0);
      for (size_t i = 0; i < view.volume.size(); ++i) view.volume[i] = uint8_t((*volume)[size_t(c)][i]);
      view.volume_columns = kAimVolumeColumns;
    }
  }
}

// The window: both views live, a 60th of a second of the fake rig each displayed frame.
int run_window(const AimOptions& o, AimRemotes& remotes, AimMonitor& monitor,
               const std::array<std::vector<VolumeCell>, 2>* volume) {
  uint32_t width = 0, height = 0;
  char tail = 0;
  if (std::sscanf(o.size.c_str(), "%ux%u%c", &width, &height, &tail) != 2 || width < 64 || height < 64 ||
      width > 8192 || height > 8192)
    return fail("--size must be WIDTHxHEIGHT, 64 to 8192 pixels a side, not '" + o.size + "'");
  std::vector<ScriptEvent> script;
  if (!o.script_path.empty()) {
    auto s = read_script(o.script_path);
    if (!s) return fail("--script: " + s.error());
    script = std::move(*s);
  }
  World world;  // nothing to draw but the HUD: the window's frame runs no system
  Scheduler scheduler = make_scheduler(world, monotonic_ns);
  auto opened = AppWindow::open(world, scheduler, width, height, {}, {});
  if (!opened) return fail(opened.error());
  AppWindow& app = **opened;
  app.hud_data.aiming = true;
  SecondLines lines;
  int64_t now_us = 0;
  app.drive_frames_with([&] {
    remotes.run_for(o.fake_rig_seed ? 1'000'000'000 / 60 : 0, monitor, [&](int64_t now) {
      now_us = now;
      lines.at(now, remotes, monitor);
    });
    fill_hud(app.hud_data, remotes, monitor, volume);
  });
  const render::Orbit orbit;
  uint64_t frame = 0;
  size_t next_script = 0;
  window::Window& win = app.window();
  while (app.status() && !win.should_close()) {
    next_script = deliver_script(script, next_script, frame, win);
    win.poll();
    for (const window::WindowEvent& e : win.events())
      if (e.kind == window::WindowEventKind::KeyPress && e.key == GLFW_KEY_ESCAPE)
        glfwSetWindowShouldClose(win.handle(), GLFW_TRUE);
    win.events().clear();
    if (!app.display(orbit) && app.status() && app.width() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(16));
    ++frame;
  }
  render::Image shot;
  if (!o.screenshot_path.empty() && app.status()) {
    app.drive_frames_with([] {});  // the picture of the state the window showed last
    bool shown = false;
    for (int attempt = 0; attempt < 3 && app.status() && !shown; ++attempt) shown = app.display(orbit, &shot);
    if (app.status() && !shown) return fail("--screenshot: the window could not be drawn (minimised?)");
  }
  if (!app.status()) return fail("Vulkan: " + app.status().error);
  const size_t messages = app.close();
  if (messages) return fail(std::to_string(messages) + " Vulkan validation message(s), see above");
  std::vector<std::string> pictures;
  if (!o.screenshot_path.empty()) {
    if (Status s = render::write_png(shot, o.screenshot_path); !s) return fail(s.error);
    pictures.push_back(o.screenshot_path);
  }
  print_summary(now_us, remotes, monitor, volume, pictures);
  return 0;
}

}  // namespace

int run_aim(const AimOptions& o) {
  if (!(o.seconds > 0 && o.seconds <= 3600)) return fail("--seconds must be above 0 and at most 3600");
  if (o.ir_sensitivity < 1 || o.ir_sensitivity > 6)
    return fail("--ir-sensitivity must be 1 to 5, or 6 for the high-sensitivity block");
  const bool headless = !o.png_dir.empty();
  if (headless && (!o.script_path.empty() || !o.screenshot_path.empty()))
    return fail("--script and --screenshot are for the window; --png-dir writes the pictures without one");
  // The rig, when there is one: the working volume each view shades, and the remotes' roles.
  std::vector<wiimote::RemoteAssignment> assigned;
  std::optional<std::array<std::vector<VolumeCell>, 2>> volume;
  if (!o.rig_path.empty()) {
    auto text = read_text_file(o.rig_path);
    if (!text) return fail("--rig: " + text.error());
    auto rig = tracking::rig_from_json(*text, o.rig_path);
    if (!rig) return fail("--rig: " + rig.error());
    auto roles = wiimote::remotes_from_rig_json(*text, o.rig_path);
    if (!roles) return fail("--rig: " + roles.error());
    assigned = std::move(*roles);
    volume = volume_cells(rig->cam0, rig->cam1);
  }
  // The pictures' folder is made before the remotes are watched, so that a bad one is said at once.
  const bool made = headless && !std::filesystem::exists(o.png_dir);
  if (headless) {
    std::error_code error;
    std::filesystem::create_directories(o.png_dir, error);
    if (error || !std::filesystem::is_directory(o.png_dir) || ::access(o.png_dir.c_str(), W_OK) != 0)
      return fail("--png-dir " + o.png_dir + ": cannot write pictures there" +
                  (error ? " (" + error.message() + ")" : std::string()));
  }
  auto remotes = AimRemotes::open(o, std::move(assigned));
  if (!remotes) {
    std::error_code ignored;
    if (made) std::filesystem::remove(o.png_dir, ignored);  // no empty folder left behind by a failed start
    return fail(remotes.error());
  }
  AimMonitor monitor(o.ir_sensitivity);
  const auto* shaded = volume ? &*volume : nullptr;
  return headless ? run_headless(o, **remotes, monitor, shaded) : run_window(o, **remotes, monitor, shaded);
}

}  // namespace fire::app
