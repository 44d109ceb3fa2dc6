#include "tools/app/calibrate_live.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <thread>

#include "platform/wiimote/driver.hpp"
#include "platform/wiimote/fake_remote.hpp"
#include "platform/wiimote/hidapi_backend.hpp"
#include "engine/camera.hpp"
#include "engine/ir_report.hpp"
#include "tools/simulation/simulate.hpp"
#include "tools/app/fake_rig.hpp"
#include "tools/app/live_session.hpp"

namespace fire::app {

namespace {

// What the wand has shown each camera: reports with both LEDs (samples for the bundle adjustment) and the
// cells of an 8 x 6 grid over the 1024 x 768 image its blobs fell in.
class WandCoverage {
 public:
  static constexpr int kColumns = 8, kRows = 6;

  void add(const InputEvent& e) {
    if (e.kind != EventKind::Hid || e.device < 0 || e.device > 1) return;
    const DecodedReport d = decode_ir_report(e.bytes);
    if (d.status != ReportStatus::Ok) return;
    Camera& c = cameras_[size_t(e.device)];
    int seen = 0;
    for (const IrSlot& s : d.report.slots) {
      if (!s.seen) continue;
      ++seen;
      const int col = std::min(kColumns - 1, s.x * kColumns / kWiimoteWidth);
      const int row = std::min(kRows - 1, s.y * kRows / kWiimoteHeight);
      c.cells[size_t(row * kColumns + col)] = true;
    }
    c.samples += seen == 2;
  }
  size_t samples(int camera) const { return cameras_[size_t(camera)].samples; }
  double covered(int camera) const {
    const auto& cells = cameras_[size_t(camera)].cells;
    return double(std::count(cells.begin(), cells.end(), true)) / double(cells.size());
  }
  bool enough(const LiveWandOptions& o) const {
    for (int c = 0; c < 2; ++c)
      if (samples(c) < o.samples || covered(c) < o.coverage) return false;
    return true;
  }
  std::string line() const {
    char text[160];
    std::snprintf(text, sizeof text, "camera 0: %zu wand samples, %.0f%% of the image covered; camera 1: %zu, %.0f%%",
                  samples(0), 100 * covered(0), samples(1), 100 * covered(1));
    return text;
  }

 private:
  struct Camera {
    size_t samples = 0;
    std::array<bool, kColumns * kRows> cells{};
  };
  std::array<Camera, 2> cameras_;
};

Result<SimulatedBlobs> simulated_wand(uint64_t seed, const LiveWandOptions& o) {
  simulation::RigOptions rig;
  rig.seed = seed;
  rig.rig_seed = seed;
  simulation::WandOptions wand;
  wand.duration_s = o.max_s;
  wand.length_m = o.wand_length_m;
  auto session = simulation::simulate_wand(rig, wand);
  if (!session) return Result<SimulatedBlobs>::failure("--fake-rig: " + session.error());
  return simulated_blobs_of(session->events);
}

// Enter on a terminal stops the recording; anything else on stdin (a pipe, /dev/null) is not a key.
bool key_pressed() {
  if (!::isatty(STDIN_FILENO)) return false;
  pollfd p{.fd = STDIN_FILENO, .events = POLLIN, .revents = 0};
  if (::poll(&p, 1, 0) <= 0) return false;
  std::string line;
  std::getline(std::cin, line);
  return true;
}

}  // namespace

Result<std::vector<InputEvent>> record_live_wand(const LiveWandOptions& o) {
  using R = Result<std::vector<InputEvent>>;
  // The fake rig waves the simulated wand once both its cameras run.
  std::unique_ptr<FakeRig> fake;
  std::unique_ptr<wiimote::Backend> hidapi;
  wiimote::Backend* backend = nullptr;
  wiimote::Clock clock = wiimote::system_clock();
  if (o.fake_rig_seed) {
    auto wand = simulated_wand(*o.fake_rig_seed, o);
    if (!wand) return R::failure(wand.error());
    fake = std::make_unique<FakeRig>(std::move(*wand), false);
    backend = &fake->backend();
    clock = fake->clock();
  } else {
    hidapi = std::make_unique<wiimote::HidapiBackend>();
    backend = hidapi.get();
  }

  wiimote::LogWriter log(clock);
  log.meta("wand_length_m", format_double(o.wand_length_m));
  wiimote::Driver driver(*backend, log, {}, {}, clock);
  auto scan = driver.open_all();
  if (!scan) return R::failure(scan.error());
  for (const std::string& e : scan->open_errors) std::cerr << "fire calibrate: " << e << "\n";
  const int cameras = driver.cameras();
  if (cameras < 2)
    return R::failure("--live needs two Wii Remotes as cameras and found " + std::to_string(cameras) +
                      " (fire devices lists what this machine sees)");

  // The folder is made once the cameras are there, so a failed start leaves none behind; the log writer
  // holds what arrived meanwhile.
  World world;  // no rig yet: the frames carry the reports to the log and nothing draws
  auto out = SessionWriter::create(o.session_dir, settings_json(world));
  if (!out) return R::failure(out.error());
  Scheduler scheduler = make_scheduler(world, [] { return int64_t{0}; });
  LiveSession live(world, scheduler, log, *out);
  std::vector<InputEvent> events;
  WandCoverage coverage;
  live.on_taken([&](std::span<const InputEvent> taken) {
    for (const InputEvent& e : taken) {
      coverage.add(e);
      events.push_back(e);
    }
  });
  std::cerr << "fire calibrate: wave the wand through the working volume; Enter stops\n";
  const int64_t start_ns = clock();
  int64_t next_progress_ns = start_ns;
  std::string stop;
  if (!o.fake_rig_seed) driver.start();
  while (stop.empty()) {
    if (fake) {
      fake->advance(1'000'000, driver);
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    live.step();
    // No pen is drawn while calibrating: the driver's pen notices ("the stroke ended") would be about the wand.
    for (const wiimote::Notice& n : driver.take_notices())
      if (n.device != wiimote::kPenNotice) std::cerr << "fire calibrate: " << wiimote::describe(n) << "\n";
    const int64_t now = clock();
    if (now >= next_progress_ns) {
      std::cerr << "fire calibrate: " << coverage.line() << "\n";
      next_progress_ns += 1'000'000'000;
    }
    if (coverage.enough(o)) stop = "both cameras have seen enough of the wand";
    else if (double(now - start_ns) * 1e-9 >= o.max_s) stop = "time is up (--max-seconds)";
    else if (key_pressed()) stop = "stopped by a key";
    if (!live.status()) return R::failure(live.status().error);
  }
  driver.stop();
  for (int k = 0; fake && k < 4; ++k) driver.poll(0);  // what the fake remotes still hold
  if (Status s = live.finish(); !s) return R::failure(s.error);
  std::cerr << "fire calibrate: " << coverage.line() << "\nfire calibrate: " << stop << "; " << events.size()
            << " events recorded in " << o.session_dir << "\n";
  return events;
}

}  // namespace fire::app
