// Seeded random editing (splits, deletes, undos, redos) with an incremental reconstruction after every
// edit: it must equal a reconstruction from scratch bit for bit, be finite, and an input the method
// cannot take must be refused with a reason, never crash.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "networks.hpp"
#include "systems/reconstruct/reconstruct.hpp"
#include "systems/split/edit.hpp"

using namespace fire;
using namespace fire::reconstruct;
using namespace fire::test;

namespace {


bool finite(const SurfaceMesh& s) {
  for (const Vec3& p : s.positions)
    if (!p.allFinite()) return false;
  for (const Vec3& n : s.normals)
    if (!n.allFinite()) return false;
  return true;
}

}  // namespace

TEST_CASE("random edits: incremental reconstruction equals a rebuild after every edit", "[reconstruct][incremental][random]") {
  std::mt19937_64 rng(20261214);
  Mesh net = grid_network(4, 3, 9, random_edit_height);
  EditHistory history;
  const Options fire_options{Method::Fire, 1, 2, Planarity::LeastSquares};
  const Options thesis_options{Method::Thesis, 1, 2, Planarity::LeastSquares};
  ReconstructionState fire_state, thesis_state;
  SurfaceMesh fire_surface, thesis_surface;
  int applied = 0, thesis_refused = 0, compared = 0, closed_steps = 0, holed_steps = 0, crossed = 0, chained_steps = 0;
  for (int step = 0; step < 120; ++step) {
    const uint64_t dice = rng() % 100;
    const std::optional<Status> edit = random_edit(net, history, rng, dice < 60, dice, 75, 90);
    if (!edit) continue;
    const Status& r = *edit;
    applied += r.ok();
    crossed += r.ok() && dice < 60 && history.last_applied()->kind == EditKind::CrossCurves;
    INFO("step " << step << " (" << (r.ok() ? "applied" : r.error) << "), " << net.face_count() << " faces");
    REQUIRE(net.validate() == "");

    const Status fire_status = reconstruct_update(net, fire_options, fire_state, fire_surface);
    INFO(fire_status.error);
    REQUIRE(fire_status.ok());
    CHECK(finite(fire_surface));
    auto fire_full = reconstruct_surface(net, fire_options);
    REQUIRE(fire_full.ok());
    CHECK(same_bytes(fire_surface.positions, fire_full->positions));
    CHECK(same_bytes(fire_surface.normals, fire_full->normals));
    CHECK(same_bytes(fire_surface.face_vertices, fire_full->face_vertices));

    // The thesis method refuses 2-sided faces, which random splits between two points of one edge make.
    const Status thesis_status = reconstruct_update(net, thesis_options, thesis_state, thesis_surface);
    if (thesis_status.ok()) {
      CHECK(finite(thesis_surface));
      auto thesis_full = reconstruct_surface(net, thesis_options);
      REQUIRE(thesis_full.ok());
      CHECK(same_bytes(thesis_surface.positions, thesis_full->positions));
      ++compared;
    } else {
      CHECK_THAT(thesis_status.error, Catch::Contains("has 2 edges"));
      ++thesis_refused;
    }
    closed_steps += net.border_loop_count() == 0;
    holed_steps += net.border_loop_count() > 1;
    chained_steps += net.pending_piece_count() > 0;
    net.begin_frame(net.frame() + 1);
  }
  // The mix really edited the network, the topology too (closed by curves across the border's hole, opened
  // again by holes, strokes across curves, strokes in pieces), and the thesis comparison really ran (seed
  // 20261214: 105 edits applied, 17 thesis comparisons, 103 refusals; 63 steps closed, 28 with more than one
  // border loop, 2 strokes across curves, 41 steps with a pending chain).
  INFO("applied " << applied << ", thesis compared " << compared << ", refused " << thesis_refused << ", closed "
                  << closed_steps << ", holed " << holed_steps << ", strokes across curves " << crossed
                  << ", steps with a pending chain " << chained_steps);
  CHECK(applied > 60);
  CHECK(crossed > 0);
  CHECK(chained_steps > 0);
  CHECK(closed_steps > 0);
  CHECK(holed_steps > 0);
  CHECK(compared > 15);
  CHECK(thesis_refused > 0);
  CHECK(net.face_count() > 12);
}
