// The live surface under a long seeded random edit sequence: the frame of every applied edit shows the
// new faces from their initial base points, not settled; the fit then ends within 6 frames (the default
// work per frame, on this grid's small base meshes) on a surface equal, bit for bit, to a reconstruction from
// scratch, writing nothing in the frames between; and the refine stage recomputes only the faces the edit
// stamped and the faces across the edges it stamped. Some edits come before the previous fit has ended,
// which abandons it.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <set>

#include "networks.hpp"
#include "systems/refine/refine_system.hpp"
#include "systems/split/edit.hpp"
#include "systems/subdivide/subdivide_system.hpp"

using namespace fire;
using namespace fire::reconstruct;
using namespace fire::test;

namespace {


// Faces the refine stage may recompute after frame `f`: those stamped in it and those using an edge
// stamped in it.
size_t local_bound(const Mesh& m, Frame f) {
  std::set<uint32_t> faces;
  for (uint32_t face : m.faces.changes.since(f - 1))
    if (m.face_alive(FaceIndex{face})) faces.insert(face);
  for (uint32_t e : m.edges.changes.since(f - 1)) {
    if (!m.edge_alive(EdgeIndex{e})) continue;
    for (uint32_t face : m.edges.face[e])
      if (face != kNone) faces.insert(face);
  }
  return faces.size();
}

}  // namespace

TEST_CASE("random edits through the frame: shown in the commit frame, settled within 6 frames equal to a full rebuild",
          "[reconstruct][incremental][random][frame]") {
#ifdef FIRE_ASSERTIONS
  const int operations = 300;  // sanitizer build: the same sequence's start, in its time budget
#else
  const int operations = 2000;
#endif
  std::mt19937_64 rng(20261201);
  Mesh net = grid_network(4, 3, 9, random_edit_height);
  EditHistory history;
  const Options options{Method::Fire, 1, 2, Planarity::LeastSquares};
  SurfaceBuild build;
  SurfaceLevels surface;
  Frame frame = 0;
  auto run_frame = [&] {
    refine_system(net, options, build);
    subdivide_system(options, FrameTime{frame, 0, 0}, build, surface);
  };
  // Frames with no edit until the surface has settled; returns how many ran. Only the last one writes.
  auto settle = [&] {
    int frames = 0;
    while (!surface.settled && frames < 100) {
      const Frame written = surface.frame;
      net.begin_frame(++frame);
      run_frame();
      ++frames;
      CHECK((surface.settled ? surface.frame == frame : surface.frame == written));
    }
    return frames;
  };
  run_frame();
  REQUIRE(surface.quad_count() > 0);
  CHECK_FALSE(surface.settled);
  CHECK(settle() <= 6);
  REQUIRE(surface.settled);
  // Which edits wait for their fit to end: a separate generator, so that the edits are the same.
  std::mt19937_64 pace(7);
  size_t applied = 0, refused = 0, faces_recomputed = 0, faces_bound = 0, topology_rebuilds = 0, limit_vertices = 0,
         interrupted = 0, joined_faces = 0, finer_faces = 0;
  int most_frames_to_settle = 0;
  bool rebuilt_from_scratch = false;  // after a refused network the next update starts over
  for (int op = 0; op < operations; ++op) {
    net.begin_frame(++frame);
    const Frame edit_frame = frame;
    const uint64_t dice = rng() % 100;
    // Splits add faces and deletes remove them; the band keeps the network between about 10 and 40 faces.
    const bool grow = net.face_count() < 10 || (net.face_count() < 40 && dice < 55);
    const std::optional<Status> edit = random_edit(net, history, rng, grow, dice, 75, 90);
    if (!edit) continue;
    const Status& r = *edit;
    applied += r.ok();
    INFO("operation " << op << " (" << (r.ok() ? "applied" : r.error) << "), " << net.face_count() << " faces");
    REQUIRE(net.validate() == "");

    const SurfaceLevels before = surface;
    run_frame();
    const UpdateStats stats = build.state.last_update();  // the settling frames' refine resets it
    auto full = reconstruct_surface(net, options);
    if (!build.problem.empty()) {
      // Random ends can make a face the method refuses (two corners at one point): refused with the
      // same reason as a full rebuild, and the last good surface stays.
      REQUIRE_FALSE(full.ok());
      CHECK(full.error() == build.problem);
      CHECK(same_bytes(surface.positions, before.positions));
      ++refused;
      rebuilt_from_scratch = true;
      continue;
    }
    REQUIRE(full.ok());
    if (r.ok()) {
      // The commit frame: the new faces shown (the final quads), provisional, the fit running.
      CHECK(surface.frame == edit_frame);
      CHECK_FALSE(surface.settled);
      CHECK(build.state.fitting());
      REQUIRE(same_bytes(surface.quads, full->face_vertices));
      if (pace() % 4 == 0) {
        // The next edit comes while the fit runs (1 to 5 frames of its at most 6).
        for (uint64_t k = 1 + pace() % 5; k > 0 && !surface.settled; --k) {
          net.begin_frame(++frame);
          run_frame();
        }
        if (!surface.settled) {
          ++interrupted;
          continue;
        }
      }
    }
    const int frames_to_settle = settle();
    most_frames_to_settle = std::max(most_frames_to_settle, frames_to_settle);
    CHECK(frames_to_settle <= 6);
    REQUIRE(surface.settled);
    CHECK_FALSE(build.state.fitting());
    if (rebuilt_from_scratch) {
      rebuilt_from_scratch = false;
    } else if (r.ok()) {
      // Faces near the edit, and those of short noisy curves the edit's change of the noise rescaled, of
      // sides whose joined vertices it changed, or of long sides split anew.
      const size_t bound =
          local_bound(net, edit_frame) + 2 * (stats.edges_rescaled + stats.edges_rejoined + stats.edges_resplit);
      CHECK(stats.faces_recomputed <= bound);
      faces_recomputed += stats.faces_recomputed;
      faces_bound += bound;
      topology_rebuilds += stats.topology_rebuilt;
      limit_vertices += surface.vertex_count();
    } else {
      CHECK(stats.faces_recomputed == 0);  // a rejected edit stamps nothing
    }
    REQUIRE(same_bytes(surface.positions, full->positions));
    REQUIRE(same_bytes(surface.normals, full->normals));
    REQUIRE(same_bytes(surface.quads, full->face_vertices));
    // The quads grouped by network face (what the renderer keeps blocks by): one patch per live face, in
    // slot order, a face's base faces with 4^(L-1) quads per corner: one base face per side, n for an
    // n-sided face, fewer where noisy curves join at a vertex of valence 2 or sides that run straight on
    // join (kStraightCornerTurn, which leaves four at least); quads, or polygons where a long side has
    // more pieces (kLongSideRatio).
    REQUIRE(surface.patch_keys.size() == net.face_count());
    REQUIRE(surface.patch_offsets.size() == net.face_count() + 1);
    CHECK(surface.patch_offsets.front() == 0);
    CHECK(surface.patch_offsets.back() == surface.quad_count());
    const BaseMesh& base = build.state.base();
    std::vector<uint32_t> base_quads(net.face_slots(), 0), base_corners(net.face_slots(), 0);
    for (uint32_t b = 0; b < base.face_count(); ++b) {
      const uint32_t corners = base.face_offsets[b + 1] - base.face_offsets[b];
      ++base_quads[base.face_source[b]];
      base_corners[base.face_source[b]] += corners;
      finer_faces += corners > 4;
    }
    for (uint32_t p = 0; p < surface.patch_count(); ++p) {
      const FaceIndex f{surface.patch_keys[p]};
      REQUIRE(net.face_alive(f));
      CHECK((p == 0 || surface.patch_keys[p - 1] < f));
      const size_t corners = net.face_loop(f).size();
      CHECK(base_quads[f] >= 2);
      CHECK(base_quads[f] <= corners);
      if (base_quads[f] < corners) {
        ++joined_faces;
        CHECK((fit_noise(net) > kExactCurveNoise || base_quads[f] >= 4));
      }
      CHECK(surface.patch_end(p) - surface.patch_begin(p) == 4 * base_corners[f]);
    }
  }
  INFO("applied " << applied << ", refused " << refused << ", faces recomputed " << faces_recomputed << " of a local bound " << faces_bound
                  << ", topology rebuilds " << topology_rebuilds << ", limit vertices evaluated " << limit_vertices
                  << ", fits interrupted by the next edit " << interrupted << ", most frames to settle "
                  << most_frames_to_settle << ", faces with joined corners " << joined_faces
                  << ", base polygons beside long sides " << finer_faces);
  CHECK(applied > size_t(operations) / 2);
  CHECK(interrupted > size_t(operations) / 50);
  CHECK(most_frames_to_settle > 1);  // the fit did spread over frames
  CHECK(refused < size_t(operations) / 20);
  CHECK(faces_recomputed > 0);
  CHECK(joined_faces > 0);  // noisy edits joined curves at vertices of valence 2, and stayed equal to a rebuild
  CHECK(finer_faces > 0);   // long sides got more pieces, and stayed equal to a rebuild
  WARN("per-stage work over " << operations << " operations: " << faces_recomputed << " face patches recomputed (bound "
                              << faces_bound << "), " << topology_rebuilds << " topology rebuilds, " << limit_vertices
                              << " limit vertices evaluated, " << joined_faces << " faces with joined corners");
}
