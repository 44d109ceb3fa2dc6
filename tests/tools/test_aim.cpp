// Issue 42, item 2: `fire aim`. The aim unit on synthetic IR reports (a still stray light, the pen seen by one
// camera alone, a 60 Hz stream, a low battery are named, each naming its camera; a clean stream, the pen resting
// and a stray beside the resting pen are not mistaken), the working volume's shading from a rig, the pictures; and
// `fire aim --fake-rig 1 --png-dir D`: both pictures show the simulated pen where the simulation put it and camera
// 1's stray light, named, checked against `fire simulate drawing`'s own reports; bad input said in words.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "engine/input_log.hpp"
#include "platform/files.hpp"
#include "platform/render/image.hpp"
#include "tests/temp_dir.hpp"
#include "tools/app/aim.hpp"
#include "tools/simulation/simulate.hpp"

using namespace fire;
using namespace fire::app;
using fire::test::TempDir;
namespace fs = std::filesystem;

namespace {

IrSlots blobs(std::initializer_list<std::array<int, 3>> list) {
  IrSlots out{};
  size_t k = 0;
  for (const auto& [x, y, size] : list) out[k++] = {true, uint16_t(x), uint16_t(y), uint8_t(size)};
  return out;
}

// Both cameras' reports from 0 to `until_us`, every `period_us[c]` (camera 1 a few milliseconds later), in
// time order, each followed by advance() and `each`; `seen(c, t)` gives what camera c shows at t.
void stream(AimMonitor& m, int64_t until_us, std::array<int64_t, 2> period_us,
            const std::function<IrSlots(int, int64_t)>& seen, const std::function<void(int64_t)>& each = {}) {
  std::array<int64_t, 2> next{0, 3'000};
  while (true) {
    const int c = next[1] < next[0] ? 1 : 0;
    const int64_t t = next[size_t(c)];
    if (t > until_us) return;
    m.report(c, t, seen(c, t));
    m.advance(t);
    if (each) each(t);
    next[size_t(c)] += period_us[size_t(c)];
  }
}

// The pen going round a circle of 150 px at half a turn a second, camera 1's view 40 px to the right.
IrSlots moving_pen(int camera, int64_t t_us) {
  const double a = std::numbers::pi * double(t_us) * 1e-6;
  return blobs({{int(512 + 150 * std::cos(a)) + 40 * camera, int(384 + 150 * std::sin(a)), 4}});
}

size_t count(const std::vector<AimProblem>& problems, AimProblemKind kind, int camera) {
  return size_t(std::count_if(problems.begin(), problems.end(),
                              [&](const AimProblem& p) { return p.kind == kind && p.camera == camera; }));
}

std::string all_text(const std::vector<AimProblem>& problems) {
  std::string s;
  for (const AimProblem& p : problems) s += p.text + "\n";
  return s;
}

}  // namespace

TEST_CASE("aim: a clean stream, the pen moving then resting in both views, names nothing", "[aim]") {
  AimMonitor m(3);
  stream(
      m, 4'000'000, {10'000, 10'000},
      [](int c, int64_t t) {
        return t < 2'000'000 ? moving_pen(c, t) : blobs({{500 + 40 * c, 400, 4}});  // rests 2 s, below the lamp's 3 s
      },
      [&](int64_t) { REQUIRE(m.problems().empty()); });
  CHECK(m.named().empty());
  for (int c = 0; c < 2; ++c) {
    CHECK(m.camera(c).rate_hz == 100);
    CHECK(m.camera(c).sensitivity == 3);
    REQUIRE(m.camera(c).blobs.size() == 1);
    CHECK(m.camera(c).blobs[0].x == 500 + 40 * c);
    CHECK_FALSE(m.camera(c).blobs[0].stray);
    CHECK(m.camera(c).strays.empty());
    // The trail: the circle's cells, and the resting point's.
    size_t cells = 0;
    for (uint32_t n : m.camera(c).trail) cells += n > 0;
    CHECK(cells > 150);
    CHECK(m.camera(c).trail[size_t((400 / kAimTrailCellPx) * kAimTrailColumns + (500 + 40 * c) / kAimTrailCellPx)] > 100);
  }
}

TEST_CASE("aim: a still light camera 1 sees and camera 0 does not is named a stray after half a second", "[aim]") {
  SECTION("the pen off") {
    AimMonitor m(3);
    stream(m, 2'000'000, {10'000, 10'000}, [](int c, int64_t t) {
      return c == 1 && t >= 200'000 ? blobs({{800 + int(t / 10'000 % 2), 600, 2}}) : IrSlots{};  // a pixel of noise
    }, [&](int64_t t) {
      // Named once it has stayed half a second, never as the pen seen by one camera.
      if (t < 200'000 + kAimStrayStillUs) CHECK(m.problems().empty());
      if (t > 200'000 + kAimStrayStillUs + 20'000) REQUIRE(count(m.problems(), AimProblemKind::StrayLight, 1) == 1);
      CHECK(count(m.problems(), AimProblemKind::PenSeenByOne, 1) == 0);
    });
    REQUIRE(m.named().size() == 1);
    CHECK(m.named()[0].kind == AimProblemKind::StrayLight);
    CHECK(m.named()[0].camera == 1);
    CHECK_THAT(m.named()[0].text, Catch::Matchers::StartsWith("camera 1 sees a still light at (80"));
    CHECK_THAT(m.named()[0].text, Catch::Matchers::Contains("that camera 0 does not: a stray light"));
    REQUIRE(m.camera(1).blobs.size() == 1);
    CHECK(m.camera(1).blobs[0].stray);
    REQUIRE(m.camera(1).strays.size() == 1);
    CHECK(std::abs(m.camera(1).strays[0].x - 800) <= 1);
    CHECK(m.camera(0).strays.empty());
  }
  SECTION("the pen lights up 0.1 s later beside it, resting in both views") {
    // As in `fire simulate drawing --seed 1`: the stray at 1.013 s, the pen on a mark at 1.112 s.
    AimMonitor m(3);
    stream(m, 1'500'000, {10'000, 10'000}, [](int c, int64_t t) {
      IrSlots s{};
      if (t >= 100'000) s = blobs({{430 + 30 * c, 500, 4}});
      if (c == 1) s[1] = {true, 870, 631, 2};
      return s;
    });
    CHECK(count(m.problems(), AimProblemKind::StrayLight, 1) == 1);
    CHECK(count(m.problems(), AimProblemKind::StrayLight, 0) == 0);
    REQUIRE(m.camera(1).blobs.size() == 2);
    for (const AimBlob& b : m.camera(1).blobs) CHECK(b.stray == (b.x == 870));
    CHECK_FALSE(m.camera(0).blobs.at(0).stray);
  }
}

TEST_CASE("aim: a still light both cameras see is named after 3 s, in each camera, as a lamp", "[aim]") {
  AimMonitor m(3);
  stream(m, 3'500'000, {10'000, 10'000}, [](int c, int64_t) { return blobs({{300 + 50 * c, 200, 3}}); },
         [&](int64_t t) {
           if (t < kAimLampStillUs) REQUIRE(m.problems().empty());
         });
  CHECK(count(m.problems(), AimProblemKind::StrayLight, 0) == 1);
  CHECK(count(m.problems(), AimProblemKind::StrayLight, 1) == 1);
  INFO(all_text(m.problems()));
  CHECK_THAT(all_text(m.problems()), Catch::Matchers::Contains("camera 0 sees a still light at (300, 200) that has not "
                                                               "moved for 3.0 s, and camera 1 sees it too: a lamp"));
}

TEST_CASE("aim: the pen seen by camera 0 and not camera 1 for over a second is named", "[aim]") {
  AimMonitor m(3);
  stream(m, 2'000'000, {10'000, 10'000},
         [](int c, int64_t t) { return c == 0 && t >= 200'000 ? moving_pen(0, t) : IrSlots{}; },
         [&](int64_t t) {
           const size_t named = count(m.problems(), AimProblemKind::PenSeenByOne, 0);
           if (t < 200'000 + kAimWindowUs) REQUIRE(named == 0);
           if (t >= 220'000 + kAimWindowUs) REQUIRE(named == 1);
           REQUIRE(count(m.problems(), AimProblemKind::PenSeenByOne, 1) == 0);
           REQUIRE(count(m.problems(), AimProblemKind::StrayLight, 0) == 0);  // it moves
         });
  REQUIRE(m.named().size() == 1);
  CHECK_THAT(m.named()[0].text, Catch::Matchers::StartsWith("camera 0 sees the pen and camera 1 does not (for 1.0 s)"));
  CHECK_THAT(m.named()[0].text, Catch::Matchers::Contains("turn camera 1 toward the pen"));
}

TEST_CASE("aim: a camera sending 60 IR reports a second is named below 80 Hz, the other not", "[aim]") {
  AimMonitor m(3);
  stream(m, 2'000'000, {16'667, 10'000}, moving_pen, [&](int64_t t) {
    if (t < kAimWindowUs) REQUIRE(m.problems().empty());  // not a whole second of reports yet
  });
  CHECK(m.camera(0).rate_hz == 60);
  CHECK(m.camera(1).rate_hz == 100);
  REQUIRE(m.problems().size() == 1);
  CHECK(m.problems()[0].kind == AimProblemKind::LowRate);
  CHECK(m.problems()[0].camera == 0);
  CHECK_THAT(m.problems()[0].text, Catch::Matchers::StartsWith("camera 0 sent 60 IR reports in the last second, below 80"));
  // A camera that stops: 0 a second later.
  m.advance(3'100'000);
  CHECK(m.camera(1).rate_hz == 0);
  CHECK(m.camera(1).blobs.empty());
  CHECK(count(m.problems(), AimProblemKind::LowRate, 1) == 1);
}

TEST_CASE("aim: a low battery is named with its camera and level", "[aim]") {
  AimMonitor m(5);
  m.battery(0, 90, false);
  m.battery(1, 12, true);
  m.advance(0);
  REQUIRE(m.problems().size() == 1);
  CHECK(m.problems()[0].text == "camera 1's battery is low (12 %): put in fresh cells before calibrating");
  CHECK(m.camera(0).battery_percent == 90);
  CHECK(m.camera(1).sensitivity == 5);
}

TEST_CASE("aim: the working volume of the simulated rig, and of cameras turned apart", "[aim]") {
  simulation::RigOptions options;
  auto rig = simulation::make_simulated_rig(options);
  REQUIRE(rig);
  const tracking::Camera &cam0 = rig->cameras[0], &cam1 = rig->cameras[1];
  const WorkingVolume v = working_volume(cam0, cam1);
  // The simulator aims both cameras at (0, 0, 0.8) within 3 cm.
  CHECK((v.centre - Vec3(0, 0, options.target_distance_m)).norm() < 0.05);
  CHECK(std::abs(v.axes.col(0).x()) > 0.99);  // across: along the baseline
  CHECK(v.axes.col(2).z() > 0.99);            // deep: away from the cameras
  auto cells = volume_cells(cam0, cam1);
  for (int c = 0; c < 2; ++c) {
    const tracking::Camera& cam = c == 0 ? cam0 : cam1;
    REQUIRE(cells[size_t(c)].size() == size_t(kAimVolumeColumns * kAimVolumeRows));
    const tracking::Vec2 p = cam.project(v.centre);
    CHECK(cells[size_t(c)][size_t(int(p.y()) / kAimVolumeCellPx * kAimVolumeColumns + int(p.x()) / kAimVolumeCellPx)] ==
          VolumeCell::BothCameras);
    const double share = overlap_share(cells[size_t(c)]);
    INFO("camera " << c << ": overlap " << share);
    CHECK(share > 0.4);
    CHECK(share < 0.95);
  }
  // Camera 1's outer edge of the image looks past the box: nothing there (camera 1 is on the right, turned left).
  CHECK(cells[1][size_t(kAimVolumeRows / 2 * kAimVolumeColumns + kAimVolumeColumns - 1)] == VolumeCell::Outside);

  // Camera 1 turned 90 degrees outward about its centre: the two views share nothing.
  tracking::Camera away = cam1;
  const Vec3 centre = cam1.centre();
  away.R = cam1.R * Eigen::AngleAxisd(-std::numbers::pi / 2, Vec3::UnitY()).toRotationMatrix();
  away.t = -away.R * centre;
  const auto apart = volume_cells(cam0, away);
  CHECK(overlap_share(apart[0]) == 0);
  CHECK(overlap_share(apart[1]) == 0);
}

TEST_CASE("aim: a camera's picture: the working volume, the trail, strays in orange, blobs growing with size", "[aim]") {
  AimCamera camera;
  camera.trail.assign(size_t(kAimTrailColumns * kAimTrailRows), 0);
  camera.trail[size_t(50 * kAimTrailColumns + 10)] = 3;  // sensor (40..43, 200..203)
  camera.blobs = {{100, 600, 1, false}, {900, 100, 8, false}, {700, 300, 2, true}};
  camera.strays = {{300, 500, 2, true}};
  std::vector<VolumeCell> volume(size_t(kAimVolumeColumns * kAimVolumeRows), VolumeCell::Outside);
  volume[0] = VolumeCell::BothCameras;  // sensor (0..7, 0..7)
  volume[1] = VolumeCell::ThisCameraOnly;
  const render::Image im = aim_picture(camera, volume);
  REQUIRE(im.width == 512);
  REQUIRE(im.height == 384);
  auto is = [&](int x, int y, const uint8_t (&c)[3]) {
    const uint8_t* p = im.pixel(uint32_t(x), uint32_t(y));
    return p[0] == c[0] && p[1] == c[1] && p[2] == c[2] && p[3] == 255;
  };
  CHECK(is(1, 1, AimColour::both));
  CHECK(is(5, 1, AimColour::this_only));
  CHECK(is(300, 300, AimColour::background));
  CHECK(is(20, 100, AimColour::trail));
  CHECK(is(50, 300, AimColour::pen));
  CHECK(is(150, 250, AimColour::stray));
  CHECK(is(350, 150, AimColour::stray));
  // The disc's radius grows with the size: 4 picture pixels for size 1, 11 for size 8.
  CHECK(is(50 + 3, 300, AimColour::pen));
  CHECK(is(50 + 6, 300, AimColour::background));
  CHECK(is(450 + 10, 50, AimColour::pen));
  CHECK(is(450 + 13, 50, AimColour::background));
  // Without a rig, no shading.
  CHECK([&] {
    const render::Image bare = aim_picture(camera, {});
    const uint8_t* p = bare.pixel(1, 1);
    return p[0] == AimColour::background[0] && p[1] == AimColour::background[1];
  }());
}

// ---------------------------------------------------------------------------------------------------------------
// The command.

namespace {

struct Run {
  int exit_code = -1;
  std::string out, err;
};

std::string quote(const std::string& s) { return "'" + s + "'"; }

Run run(const std::string& command, const fs::path& dir) {
  const std::string out = (dir / "stdout").string(), err = (dir / "stderr").string();
  const int status = std::system((command + " >" + quote(out) + " 2>" + quote(err) + " </dev/null").c_str());
  Run r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (auto text = read_text_file(out)) r.out = *text;
  if (auto text = read_text_file(err)) r.err = *text;
  return r;
}

Run fire_aim(const std::string& args, const fs::path& dir) {
  return run("env -u DISPLAY -u WAYLAND_DISPLAY " + quote(FIRE_BINARY) + " aim " + args, dir);
}

nlohmann::json last_line(const std::string& out) {
  std::istringstream in(out);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return nlohmann::json::parse(last);
}

bool colour(const render::Image& im, int x, int y, const uint8_t (&c)[3]) {
  if (x < 0 || y < 0 || x >= int(im.width) || y >= int(im.height)) return false;
  const uint8_t* p = im.pixel(uint32_t(x), uint32_t(y));
  return p[0] == c[0] && p[1] == c[1] && p[2] == c[2];
}

size_t pixels(const render::Image& im, const uint8_t (&c)[3]) {
  size_t n = 0;
  for (uint32_t y = 0; y < im.height; ++y)
    for (uint32_t x = 0; x < im.width; ++x) n += colour(im, int(x), int(y), c);
  return n;
}

struct SimBlob {
  double t_s;
  int x, y, size;
};

}  // namespace

TEST_CASE("fire aim --fake-rig 1 --png-dir: the simulated pen where the simulation put it, camera 1's stray named",
          "[aim][cli]") {
  TempDir dir;
  const fs::path pictures = dir.path / "pictures";
  // The simulation's true cameras as a rig file: the working volume to shade.
  simulation::RigOptions rig_options;
  auto rig_json = simulation::true_rig_json(rig_options);
  REQUIRE(rig_json);
  const std::string rig = (dir.path / "rig.json").string();
  REQUIRE(write_file_atomic(rig, *rig_json));
  // What the fake rig shows: `fire simulate drawing` with the same seeds, its camera reports read back.
  const std::string sim = (dir.path / "sim.log").string();
  const Run simulated = run(quote(FIRE_BINARY) + " simulate drawing --seed 1 --rig-seed 1 -o " + quote(sim) +
                                " --marks-out " + quote((dir.path / "m.json").string()) + " --object-out " +
                                quote((dir.path / "o.obj").string()),
                            dir.path);
  REQUIRE(simulated.exit_code == 0);
  auto log = read_input_log(sim);
  REQUIRE(log);
  std::array<std::vector<SimBlob>, 2> seen;
  for (const InputEvent& e : log->events) {
    if (e.kind != EventKind::Hid || e.device < 0 || e.device > 1) continue;
    const DecodedReport d = decode_ir_report(e.bytes);
    for (const IrSlot& s : d.report.slots)
      if (s.seen) seen[size_t(e.device)].push_back({double(e.t_us) * 1e-6, s.x, s.y, s.size});
  }
  // The simulator's stray reflection: the blobs of size 2 (the pen 0.6 to 1 m away has 3 to 5), camera 1's only.
  std::vector<SimBlob> stray;
  for (const SimBlob& b : seen[1])
    if (b.size == 2 && b.t_s < 5) stray.push_back(b);
  REQUIRE(stray.size() > 50);
  for (const SimBlob& b : seen[0]) REQUIRE(b.size != 2);

  const Run aim = fire_aim("--fake-rig 1 --rig " + quote(rig) + " --png-dir " + quote(pictures.string()), dir.path);
  INFO("stdout: " << aim.out << "\nstderr: " << aim.err);
  REQUIRE(aim.exit_code == 0);
  const nlohmann::json end = last_line(aim.out);
  const double t_end = end["t_s"].get<double>();
  CHECK(t_end >= 5.0);  // --seconds' default
  CHECK(t_end < 5.1);
  // One problem in 5 s: the stray, named for camera 1 at the simulator's spot.
  REQUIRE(end["problems_named"].size() == 1);
  const std::string named = end["problems_named"][0];
  CHECK_THAT(named, Catch::Matchers::StartsWith("camera 1 sees a still light at (87"));
  CHECK_THAT(named, Catch::Matchers::Contains("that camera 0 does not: a stray light"));
  CHECK(end["cameras"][0]["strays"].empty());
  REQUIRE(end["cameras"][1]["strays"].size() == 1);
  const int stray_x = end["cameras"][1]["strays"][0]["x"], stray_y = end["cameras"][1]["strays"][0]["y"];
  for (const SimBlob& b : stray) {
    CHECK(std::abs(b.x - stray_x) <= 2);
    CHECK(std::abs(b.y - stray_y) <= 2);
  }
  for (int c = 0; c < 2; ++c) {
    CHECK(end["cameras"][c]["rate_hz"].get<int>() >= 95);
    CHECK(end["cameras"][c]["state"] == "running");
    CHECK(end["overlap"][c].get<double>() > 0.4);
  }
  CHECK(end["pictures"] == nlohmann::json{(pictures / "camera0.png").string(), (pictures / "camera1.png").string()});
  // A line a second before it.
  CHECK(aim.out.find("{\"t_s\":4,") != std::string::npos);

  std::array<render::Image, 2> im;
  for (int c = 0; c < 2; ++c) {
    auto read = render::read_png((pictures / ("camera" + std::to_string(c) + ".png")).string());
    REQUIRE(read);
    im[size_t(c)] = std::move(*read);
    REQUIRE(im[size_t(c)].width == 512);
    REQUIRE(im[size_t(c)].height == 384);
    // The working volume of the true rig, shaded.
    CHECK(double(pixels(im[size_t(c)], AimColour::both)) > 0.3 * 512 * 384);
  }
  // The stray in orange in camera 1's picture where the simulator put it; none in camera 0's.
  size_t orange = 0;
  for (int dy = -6; dy <= 6; ++dy)
    for (int dx = -6; dx <= 6; ++dx) orange += colour(im[1], stray_x / 2 + dx, stray_y / 2 + dy, AimColour::stray);
  CHECK(orange > 50);
  CHECK(pixels(im[0], AimColour::stray) == 0);
  // The pen lit at the end: its blobs in white, where the simulation's reports put it then.
  for (int c = 0; c < 2; ++c) {
    const auto& last = end["cameras"][c]["blobs"];
    REQUIRE(last.size() == 1);
    const int x = last[0]["x"], y = last[0]["y"];
    CHECK_FALSE(last[0]["stray"].get<bool>());
    CHECK(colour(im[size_t(c)], x / 2, y / 2, AimColour::pen));
    bool near = false;
    for (const SimBlob& b : seen[size_t(c)])
      near = near || (std::abs(b.t_s - t_end) < 0.05 && std::hypot(b.x - x, b.y - y) < 4);
    CHECK(near);
  }
  // The trail: every pen blob the simulation's cameras reported until shortly before the end is drawn.
  for (int c = 0; c < 2; ++c) {
    size_t blobs = 0, drawn = 0;
    for (const SimBlob& b : seen[size_t(c)]) {
      if (b.t_s < 0.05 || b.t_s > t_end - 0.05 || b.size == 2) continue;
      ++blobs;
      bool hit = false;
      for (int dy = -2; dy <= 2 && !hit; ++dy)
        for (int dx = -2; dx <= 2 && !hit; ++dx)
          hit = colour(im[size_t(c)], b.x / 2 + dx, b.y / 2 + dy, AimColour::trail) ||
                colour(im[size_t(c)], b.x / 2 + dx, b.y / 2 + dy, AimColour::pen);
      drawn += hit;
    }
    INFO("camera " << c << ": " << drawn << " of " << blobs << " simulated pen blobs drawn");
    CHECK(blobs > 200);
    CHECK(drawn == blobs);
  }

  // Without a rig: no shading, and a word on what it needs.
  const Run bare = fire_aim("--fake-rig 1 --seconds 1 --png-dir " + quote(pictures.string()), dir.path);
  REQUIRE(bare.exit_code == 0);
  CHECK(bare.err.find("needs a rig: give --rig RIG.json") != std::string::npos);
  // No pen is drawn while aiming: the driver's words about one ("pen: the stroke ended") are not shown.
  CHECK(bare.err.find("pen: ") == std::string::npos);
  CHECK(last_line(bare.out)["overlap"].is_null());
  auto plain = render::read_png((pictures / "camera0.png").string());
  REQUIRE(plain);
  CHECK(pixels(*plain, AimColour::both) == 0);
  CHECK(pixels(*plain, AimColour::this_only) == 0);
}

TEST_CASE("fire aim misused, or without remotes: a clear message naming the input, exit 1", "[aim][cli]") {
  TempDir dir;
  const std::string missing = (dir.path / "missing.json").string();
  const Run no_rig = fire_aim("--fake-rig 1 --png-dir " + quote((dir.path / "p").string()) + " --rig " + quote(missing),
                              dir.path);
  CHECK(no_rig.exit_code == 1);
  CHECK(no_rig.err.find("fire aim: --rig: ") != std::string::npos);
  CHECK(no_rig.err.find("missing.json") != std::string::npos);

  const std::string bad = (dir.path / "bad.json").string();
  REQUIRE(write_file_atomic(bad, "{\"format\": \"fire-marks\"}"));
  const Run bad_rig = fire_aim("--fake-rig 1 --png-dir " + quote((dir.path / "p").string()) + " --rig " + quote(bad),
                               dir.path);
  CHECK(bad_rig.exit_code == 1);
  CHECK(bad_rig.err.find("bad.json") != std::string::npos);

  // A folder that cannot be made: below a file.
  const Run unwritable = fire_aim("--fake-rig 1 --png-dir " + quote(bad + "/pictures"), dir.path);
  CHECK(unwritable.exit_code == 1);
  CHECK(unwritable.err.find("fire aim: --png-dir " + bad + "/pictures: cannot write pictures there") != std::string::npos);

  const Run seconds = fire_aim("--fake-rig 1 --seconds nan --png-dir " + quote((dir.path / "p").string()), dir.path);
  CHECK(seconds.exit_code == 1);
  CHECK(seconds.err.find("--seconds must be") != std::string::npos);
  const Run hooks = fire_aim("--fake-rig 1 --png-dir " + quote((dir.path / "p").string()) + " --screenshot x.png", dir.path);
  CHECK(hooks.exit_code == 1);
  CHECK(hooks.err.find("are for the window") != std::string::npos);
  const Run no_display = fire_aim("--fake-rig 1", dir.path);
  CHECK(no_display.exit_code == 1);
  CHECK(no_display.err.find("no display") != std::string::npos);

  CHECK_FALSE(fs::exists(dir.path / "p"));  // none of these made the pictures' folder

  // No --fake-rig: the remotes of this machine, which CI has none of; no empty folder is left behind.
  const fs::path none_dir = dir.path / "none";
  const Run none = fire_aim("--png-dir " + quote(none_dir.string()) + " --seconds 1", dir.path);
  INFO("stderr: " << none.err);
  if (none.exit_code == 0) {
    WARN("this machine has two Wii Remotes: the no-remote case is not checked");
  } else {
    CHECK(none.exit_code == 1);
    CHECK(none.err.find("fire aim: needs two Wii Remotes as cameras and found 0") != std::string::npos);
    CHECK(none.err.find("fire devices lists") != std::string::npos);
    CHECK_FALSE(fs::exists(none_dir));
  }
}
