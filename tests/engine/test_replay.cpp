// Replaying a log through the frame systems: deterministic, and bad strokes rejected without loss.
#include <catch2/catch.hpp>

#include "tools/fire/session.hpp"

using namespace fire;

namespace {

int64_t fake_clock() {
  static int64_t t = 0;
  return t += 1000;
}

std::unique_ptr<World> replay_text(const std::string& text) {
  auto log = parse_input_log(text, "mem.log");
  REQUIRE(log.ok());
  auto w = std::make_unique<World>();
  w->log = std::move(*log);
  Scheduler s = make_scheduler(*w, fake_clock);
  replay_headless(*w, s);
  return w;
}

std::string stroke(int64_t& t, std::initializer_list<Vec3> pts) {
  std::string s = std::to_string(t) + " down\n";
  for (const Vec3& p : pts) {
    t += 10000;
    s += std::to_string(t) + " pen " + format_double(p.x()) + " " + format_double(p.y()) + " " + format_double(p.z()) + "\n";
  }
  t += 10000;
  s += std::to_string(t) + " up\n";
  t += 100000;
  return s;
}

}  // namespace

TEST_CASE("the demo log replays to the same pools every time", "[replay]") {
  auto log = read_input_log(FIRE_SOURCE_DIR "/tools/demo/sketch.log");
  REQUIRE(log.ok());
  uint64_t hashes[2];
  for (uint64_t& hash : hashes) {
    auto w = std::make_unique<World>();
    w->log = *log;
    Scheduler s = make_scheduler(*w, fake_clock);
    replay_headless(*w, s);
    REQUIRE(w->mesh.validate() == "");
    CHECK(w->mesh.face_count() == 14);
    CHECK(w->rejections.size() == 1);
    CHECK(s.timings().size() == 3);
    hash = w->mesh.hash();
  }
  CHECK(hashes[0] == hashes[1]);
}

TEST_CASE("strokes become a border, a split, and an undo", "[replay]") {
  int64_t t = 0;
  std::string text = "FIRE-LOG 1\n";
  text += stroke(t, {{0, 0, 0}, {0.05, 0, 0}, {0.1, 0, 0}});
  text += stroke(t, {{0.1, 0, 0}, {0.1, 0.05, 0}, {0.1, 0.1, 0}});
  text += stroke(t, {{0.1, 0.1, 0}, {0.05, 0.1, 0}, {0, 0.1, 0}});
  text += stroke(t, {{0, 0.1, 0}, {0, 0.05, 0}, {0.002, 0.001, 0}});  // closes: within 1 cm of the start
  auto w = replay_text(text);
  CHECK(w->mesh.face_count() == 1);
  CHECK(w->mesh.edge_count() == 4);
  text += stroke(t, {{0.051, 0.001, 0}, {0.05, 0.05, 0.01}, {0.049, 0.099, 0}});  // middle of bottom to middle of top
  w = replay_text(text);
  CHECK(w->mesh.face_count() == 2);
  CHECK(w->mesh.vertex_count() == 6);
  CHECK(w->rejections.empty());
  std::string undone = text + std::to_string(t) + " cmd undo\n";
  w = replay_text(undone);
  CHECK(w->mesh.face_count() == 1);
  std::string deleted = text + std::to_string(t) + " cmd delete 0.05 0.05 0.01\n";
  w = replay_text(deleted);
  CHECK(w->mesh.face_count() == 1);
  CHECK(w->mesh.vertex_count() == 4);
}

TEST_CASE("a stroke with NaN or ends on two faces is rejected and nothing drawn is lost", "[replay][reject]") {
  int64_t t = 0;
  std::string text = "FIRE-LOG 1\n";
  text += stroke(t, {{0, 0, 0}, {0.1, 0, 0}});
  text += stroke(t, {{0.1, 0, 0}, {0.1, 0.1, 0}});
  text += stroke(t, {{0.1, 0.1, 0}, {0, 0.1, 0}});
  text += stroke(t, {{0, 0.1, 0}, {0, 0, 0}});
  auto clean = replay_text(text);
  std::string bad = text + stroke(t, {{0.05, 0, 0}, {std::nan(""), 0.05, 0}, {0.05, 0.1, 0}});
  bad += stroke(t, {{0.05, 0.3, 0}, {0.05, 0.5, 0}});  // nowhere near the network
  auto w = replay_text(bad);
  REQUIRE(w->rejections.size() == 2);
  CHECK_THAT(w->rejections[0].reason, Catch::Matchers::Contains("not finite"));
  CHECK_THAT(w->rejections[1].reason, Catch::Matchers::Contains("does not start and end"));
  CHECK(w->rejections[0].line > 0);
  CHECK(w->mesh.same_pools(clean->mesh));
}
