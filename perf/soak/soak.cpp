// The soak (issue 14): a long seeded run of random edits on one drawing, in the steady state a long session
// reaches. Each operation is a frame: a split, a delete, an undo, a redo, a compaction, or (rarely) a new
// drawing started from a fresh border. The face count is kept in a band and the undo history capped, so
// the run measures a steady state rather than a growing mesh. After every operation the pools validate and
// the snapping index syncs; every `--surface-every` operations the refine and subdivide systems update the
// surface from every change since they last ran; every `--check-every` operations the snapping index
// validates and the settled surface is compared, bit for bit, with a full rebuild. Prints operations per second, peak memory, and resident memory at the start and the end.
// Any violation stops the run with the operation, the seed and the reason, and exits 1.
#include <time.h>

#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstring>
#include <random>
#include <string>

#include "engine/mesh.hpp"
#include "engine/snap_index.hpp"
#include "perf/soak/memory.hpp"
#include "systems/reconstruct/reconstruct.hpp"
#include "systems/refine/refine_system.hpp"
#include "systems/split/edit.hpp"
#include "systems/subdivide/subdivide_system.hpp"
#include "tests/systems/reconstruct/networks.hpp"

using namespace fire;
using soak::peak_mib;
using soak::resident_mib;

namespace {

struct Settings {
  uint64_t operations = 1'000'000;
  uint64_t seed = 20261201;
  uint32_t min_faces = 10, max_faces = 40;
  uint64_t check_every = 1000;
  uint64_t surface_every = 25;
  size_t history_cap = 200;
  uint32_t levels = 1;
};

double seconds_now() {
  timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

template <class T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// A square border with bowed sides, drawn as a person would: start, two appends, close.
bool draw_border(Mesh& mesh, EditHistory& history, std::mt19937_64& rng, std::string& why) {
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  const Vec3 corner[4] = {Vec3(0, 0, 0), Vec3(4 + jitter(rng), 0, 0), Vec3(4, 3 + jitter(rng), 0), Vec3(0, 3, 0)};
  for (int side = 0; side < 4; ++side) {
    EditCommand c;
    c.kind = side == 0 ? EditKind::StartBorder : side == 3 ? EditKind::CloseBorder : EditKind::AppendBorder;
    c.snap_distance = 1e-6;
    const Vec3 a = corner[side], b = corner[(side + 1) % 4];
    for (int k = 0; k < 12; ++k) {
      const double s = k / 11.0;
      c.points.push_back(a + (b - a) * s + Vec3(0, 0, 0.3 * std::sin(M_PI * s)));
    }
    if (auto r = history.apply(mesh, c); !r.ok()) {
      why = "border side " + std::to_string(side) + ": " + r.error;
      return false;
    }
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  Settings s;
  CLI::App app{"FIRE soak: seeded random edits on one drawing, checked after every operation (issue 14)"};
  app.add_option("--operations", s.operations, "operations to run")->capture_default_str();
  app.add_option("--seed", s.seed, "random seed")->capture_default_str();
  app.add_option("--min-faces", s.min_faces, "below this many faces, only splits")->capture_default_str();
  app.add_option("--max-faces", s.max_faces, "above this many faces, no splits")->capture_default_str();
  app.add_option("--check-every", s.check_every, "operations between full checks (index, surface vs rebuild)")
      ->capture_default_str();
  app.add_option("--surface-every", s.surface_every,
                 "operations between surface updates (the refine system takes every change since its last run); "
                 "a divisor of --check-every")
      ->capture_default_str();
  app.add_option("--history-cap", s.history_cap, "undo steps kept before the history is forgotten at a compaction")
      ->capture_default_str();
  app.add_option("--levels", s.levels, "subdivision levels of the surface")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (s.min_faces < 1 || s.max_faces <= s.min_faces || s.check_every == 0 || s.surface_every == 0 ||
      s.check_every % s.surface_every != 0 || s.levels < 1 ||
      s.levels > reconstruct::kMaxSurfaceLevels) {
    std::fprintf(stderr,
                 "soak: need 1 <= --min-faces < --max-faces, --check-every >= 1 and a multiple of --surface-every >= 1, "
                 "1 <= --levels <= %u\n",
                 reconstruct::kMaxSurfaceLevels);
    return 2;
  }

  const reconstruct::Options options{reconstruct::Method::Fire, 1, s.levels, reconstruct::Planarity::LeastSquares};
  std::mt19937_64 rng(s.seed);
  Mesh mesh;
  EditHistory history;
  SnapIndex snap;
  reconstruct::SurfaceBuild build;
  SurfaceLevels surface;
  std::string why;
  auto fail = [&](uint64_t op, const std::string& reason) {
    std::fprintf(stderr, "soak: violation at operation %llu (seed %llu): %s\n", (unsigned long long)op,
                 (unsigned long long)s.seed, reason.c_str());
    return 1;
  };
  if (!draw_border(mesh, history, rng, why)) return fail(0, why);

  uint64_t applied = 0, rejected = 0, compactions = 0, borders = 1, checks = 0, refused_surfaces = 0;
  uint64_t closed = 0, holed = 0;  // operations after which the network had no border loop, or more than one
  uint64_t crossings = 0, chained = 0;  // strokes across curves applied; operations after which a chain was pending
  const double rss_start = resident_mib();
  const double t0 = seconds_now();
  double next_report = t0 + 10;
  for (uint64_t op = 1; op <= s.operations; ++op) {
    mesh.begin_frame(op);
    const uint64_t dice = rng() % 1000;
    Status r;  // success unless an operation below says otherwise
    if (dice == 0) {
      // A new drawing: everything forgotten, a fresh border.
      mesh = Mesh();
      mesh.begin_frame(op);
      history = EditHistory();
      snap.clear();
      build = reconstruct::SurfaceBuild();
      surface = SurfaceLevels();
      if (!draw_border(mesh, history, rng, why)) return fail(op, why);
      ++borders;
    } else if (dice < 15 || history.undo_depth() > s.history_cap) {
      // Compaction at the sync point, which forgets the history (it cannot be undone).
      history.clear(mesh);
      mesh.compact();
      ++compactions;
    } else {
      const bool split = mesh.face_count() < s.min_faces || (mesh.face_count() < s.max_faces && dice < 550);
      if (auto edit = test::random_edit(mesh, history, rng, split, dice, 750, 900)) r = std::move(*edit);
      crossings += split && r.ok() && history.last_applied()->kind == EditKind::CrossCurves;
    }
    (r.ok() ? applied : rejected) += 1;
    if (mesh.face_count() > 0) {
      const size_t loops = mesh.border_loop_count();
      closed += loops == 0;
      holed += loops > 1;
      chained += mesh.pending_piece_count() > 0;
    }
    if (auto bad = mesh.validate(); !bad.empty()) return fail(op, "pools: " + bad);
    snap.sync(mesh);
    if (op % s.surface_every == 0) {
      refine_system(mesh, options, build);
      subdivide_system(options, FrameTime{op, 0, 0}, build, surface);
    }

    if (op % s.check_every == 0) {
      ++checks;
      if (auto bad = snap.validate(mesh); !bad.empty()) return fail(op, "snapping index: " + bad);
      // The fit of the last commit spreads over the frames after it (subdivide_system.hpp): run them.
      while (build.problem.empty() && build.state.fitting())
        subdivide_system(options, FrameTime{op, 0, 0}, build, surface);
      auto full = reconstruct::reconstruct_surface(mesh, options);
      if (!build.problem.empty()) {
        // A face the method refuses: the full rebuild must refuse it with the same reason.
        if (full.ok() || full.error() != build.problem)
          return fail(op, "the live surface refused the network (" + build.problem + ") but a rebuild did not agree");
        ++refused_surfaces;
      } else {
        if (!full.ok()) return fail(op, "a rebuild refused a network the live surface accepted: " + full.error());
        if (!same_bytes(surface.positions, full->positions) || !same_bytes(surface.normals, full->normals) ||
            !same_bytes(surface.quads, full->face_vertices))
          return fail(op, "the settled surface differs from a full rebuild");
      }
    }
    if (const double now = seconds_now(); now >= next_report) {
      next_report = now + 10;
      std::fprintf(stderr, "soak: %llu of %llu operations, %.0f per second, %zu faces, RSS %.1f MiB\n",
                   (unsigned long long)op, (unsigned long long)s.operations, double(op) / (now - t0),
                   mesh.face_count(), resident_mib());
    }
  }
  const double elapsed = seconds_now() - t0;
  std::printf("soak: %llu operations (seed %llu): 0 violations\n", (unsigned long long)s.operations,
              (unsigned long long)s.seed);
  std::printf("  applied %llu, rejected %llu, compactions %llu, new drawings %llu, full checks %llu (%llu on a "
              "network the method refuses)\n",
              (unsigned long long)applied, (unsigned long long)rejected, (unsigned long long)compactions,
              (unsigned long long)borders, (unsigned long long)checks, (unsigned long long)refused_surfaces);
  std::printf("  topology: closed after %llu operations, with more than one border loop (holes) after %llu; %llu strokes "
              "across curves applied, a stroke in pieces pending after %llu\n",
              (unsigned long long)closed, (unsigned long long)holed, (unsigned long long)crossings, (unsigned long long)chained);
  std::printf("  %.1f s, %.0f operations per second; resident memory %.1f MiB at the start, %.1f MiB at the end, "
              "peak %.1f MiB\n",
              elapsed, double(s.operations) / elapsed, rss_start, resident_mib(), peak_mib());
  return 0;
}
