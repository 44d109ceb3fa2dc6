// The simulated rig alone: deterministic logs for a seed and options, and options no rig can have refused. The
// rig's bytes against its truth, and the sessions it feeds calibrated and tracked, are tested with the truth
// reader and the tracker in tests/tools/simulation/.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "engine/input_log.hpp"
#include "platform/simulated_rig/simulated_rig.hpp"
#include "tests/platform/simulated_rig/sessions.hpp"

using namespace fire;
using namespace fire::simulation;
using namespace fire::simulation::test;

TEST_CASE("a simulated session is byte-identical for the same seed and options") {
  RigOptions rig;
  rig.seed = 3;
  const WandOptions wand{.duration_s = 2, .length_m = 0.3};
  const std::string a = format_input_log(simulate_wand(rig, wand)->events);
  const std::string b = format_input_log(simulate_wand(rig, wand)->events);
  CHECK(a == b);
  const std::string s1 = format_input_log(simulate_sketch(rig, short_sketch(), pawn().view())->events);
  const std::string s2 = format_input_log(simulate_sketch(rig, short_sketch(), pawn().view())->events);
  CHECK(s1 == s2);
  RigOptions other = rig;
  other.seed = 4;
  CHECK(format_input_log(simulate_wand(other, wand)->events) != a);
  // The rig follows rig_seed alone: a different noise seed keeps the cameras.
  CHECK(make_simulated_rig(other)->cameras[1].t == make_simulated_rig(rig)->cameras[1].t);
}

TEST_CASE("options no rig can have are refused with a reason") {
  RigOptions bad;
  bad.noise_px = -1;
  CHECK_FALSE(simulate_wand(bad, WandOptions{}).ok());
  RigOptions nan_focal;
  nan_focal.focal_px = std::nan("");
  CHECK_FALSE(make_simulated_rig(nan_focal).ok());
  CHECK_FALSE(simulate_wand(RigOptions{}, WandOptions{.duration_s = 0, .length_m = 0.3}).ok());
  const std::vector<Vec3> flat{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<uint32_t> offsets{0, 3}, faces{0, 1, 2};
  const Result<SimulatedSession> s = simulate_sketch(RigOptions{}, short_sketch(), PolygonMeshView{flat, offsets, faces});
  REQUIRE_FALSE(s.ok());
  CHECK(s.error().find("flat") != std::string::npos);
}
