// FIRE's Catmull-Clark against OpenSubdiv 3.5 (Debian libosd-dev), single thread, one process, on the pawn
// control mesh and on the pawn's base mesh after one Coons step (thesis pipeline), to levels 3 and 4:
//  (a) topology and positions from scratch: build_refinement + evaluate vs
//      TopologyRefinerFactory::Create + RefineUniform + PrimvarRefiner::Interpolate;
//  (b) positions only, topology fixed, points moved: evaluate (level by level, stencils applied from
//      the level arrays), explicit stencil tables level by level, and the factorized table, vs
//      Far::StencilTable::UpdateValues (factorized last level, and level by level).
// Prints one Markdown table row per case with medians over the repetitions, then each case's two ratios (the
// fastest OpenSubdiv over ours, from scratch and with points moved) against perf/subdivide/baseline.json and
// issue 45's targets (3x and 4x); --write-baseline keeps this run's ratios there.
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/stencilTableFactory.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <algorithm>
#include <ctime>
#include <functional>
#include <malloc.h>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "engine/surface.hpp"
#include "perf/baseline.hpp"
#include "platform/obj.hpp"
#include "systems/reconstruct/reconstruct.hpp"
#include "systems/catmull_clark/catmull_clark.hpp"
#include "systems/synth/network_from_mesh.hpp"
#include "tests/systems/catmull_clark/osd_reference.hpp"

namespace {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;
namespace sd = fire::catmull_clark;
// The oracle test's OpenSubdiv setup: the same vertex type and the options we claim to match.
using fire::osd_reference::in_osd_numbering;
using fire::osd_reference::Point;
using fire::osd_reference::to_points;
using fire::Vec3;

// Times variants in thread CPU time: the machine is shared, and time spent preempted by other
// processes is not ours (page faults, charged to the thread, are counted). Interleaved (A B C A B C
// ...), every variant runs after the others have used the caches, as in a frame loop; warm (A A A B B
// B ...), each runs on caches it filled itself.
double thread_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * double(t.tv_sec) + 1e-6 * double(t.tv_nsec);
}

struct Variant {
  std::function<void()> run;
  std::vector<double> times;
  double median() {
    std::sort(times.begin(), times.end());
    return times[times.size() / 2];
  }
};

enum class Order { Interleaved, Warm };

// before_each runs untimed before every repetition (it moves the points in part b).
void time_variants(Order order, int repetitions, std::vector<Variant*> variants,
                   const std::function<void()>& before_each) {
  auto once = [&](Variant* variant) {
    before_each();
    const double start = thread_ms();
    variant->run();
    variant->times.push_back(thread_ms() - start);
  };
  if (order == Order::Interleaved) {
    for (int i = 0; i < repetitions; ++i)
      for (Variant* variant : variants) once(variant);
  } else {
    for (Variant* variant : variants)
      for (int i = 0; i < repetitions; ++i) once(variant);
  }
}

struct Mesh {
  std::string name;
  std::vector<Vec3> positions;
  std::vector<uint32_t> face_offsets, face_vertices;
};

// OpenSubdiv's input, prepared once outside the timings (as ours takes the arrays as they are).
struct OsdInput {
  std::vector<int> sizes;
  std::vector<Far::Index> indices;
  Far::TopologyDescriptor descriptor;
  explicit OsdInput(const Mesh& mesh) {
    for (size_t f = 0; f + 1 < mesh.face_offsets.size(); ++f)
      sizes.push_back(int(mesh.face_offsets[f + 1] - mesh.face_offsets[f]));
    indices.assign(mesh.face_vertices.begin(), mesh.face_vertices.end());
    descriptor.numVertices = int(mesh.positions.size());
    descriptor.numFaces = int(sizes.size());
    descriptor.numVertsPerFace = sizes.data();
    descriptor.vertIndicesPerFace = indices.data();
  }
  std::unique_ptr<Far::TopologyRefiner> refine(int levels, bool full_last_level) const {
    return fire::osd_reference::refine_uniform(descriptor, levels, full_last_level);
  }
};

// Last-level points by Interpolate, level by level, into `levels` (resized once).
const std::vector<Point>& osd_interpolate(const Far::TopologyRefiner& refiner, const std::vector<Point>& base,
                                          std::vector<std::vector<Point>>& levels) {
  levels.resize(refiner.GetMaxLevel() + 1);
  levels[0] = base;
  Far::PrimvarRefiner primvar(refiner);
  for (int l = 1; l <= refiner.GetMaxLevel(); ++l) {
    levels[l].resize(refiner.GetLevel(l).GetNumVertices());
    const Point* src = levels[l - 1].data();
    Point* dst = levels[l].data();
    primvar.Interpolate(l, src, dst);
  }
  return levels.back();
}

double max_difference(const std::vector<Vec3>& ours, const Point* theirs) {
  double worst = 0;
  for (size_t i = 0; i < ours.size(); ++i)
    worst = std::max(worst, (ours[i] - Vec3(theirs[i].xyz[0], theirs[i].xyz[1], theirs[i].xyz[2])).norm());
  return worst;
}

// Small deterministic moves of every base point, different each call.
void move_points(std::vector<Vec3>& points, uint64_t& state) {
  for (Vec3& p : points)
    for (int axis = 0; axis < 3; ++axis) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      p[axis] += 1e-3 * (double(state >> 11) / double(1ull << 53) - 0.5);
    }
}

// Issue 45: the fastest OpenSubdiv configuration measured over ours, from scratch and with points moved.
constexpr double kScratchTarget = 3.0, kMovingTarget = 4.0;

// Prints the case's row and returns its two ratios.
std::vector<fire::perf::Figure> run_case(const Mesh& mesh, int levels, int repetitions, Order order) {
  const sd::BaseTopology topology{uint32_t(mesh.positions.size()), mesh.face_offsets, mesh.face_vertices, {}};
  const OsdInput osd_input(mesh);
  const std::vector<Point> osd_base = to_points(mesh.positions);
  std::vector<Vec3> last, scratch;
  std::vector<std::vector<Point>> osd_levels;
  sd::Refinement scratch_refinement;  // the last one built in (a), to compare its points

  // (a) From scratch. Ours without and with the last level's adjacency, OpenSubdiv without and with
  // fullTopologyInLastLevel (its default is without).
  auto ours_scratch = [&](bool adjacency) {
    auto refinement = sd::build_refinement(topology, {levels, adjacency});
    if (!refinement) std::abort();
    sd::evaluate(*refinement, mesh.positions, last, scratch);
    scratch_refinement = std::move(*refinement);
  };
  auto osd_scratch = [&](bool full) {
    auto refiner = osd_input.refine(levels, full);
    osd_interpolate(*refiner, osd_base, osd_levels);
  };
  Variant a_ours{[&] { ours_scratch(false); }, {}}, a_osd{[&] { osd_scratch(false); }, {}};
  Variant a_ours_full{[&] { ours_scratch(true); }, {}}, a_osd_full{[&] { osd_scratch(true); }, {}};
  time_variants(order, repetitions, {&a_ours, &a_osd, &a_ours_full, &a_osd_full}, [] {});
  const double a_check = max_difference(in_osd_numbering(scratch_refinement, last), osd_levels.back().data());

  // (b) Positions only. Tables built once; every repetition moves the base points first (not timed).
  auto refinement = sd::build_refinement(topology, {levels, false});
  const sd::StencilTable factorized = sd::factorize(*refinement);
  std::vector<sd::StencilTable> explicit_tables;
  for (int l = 0; l < levels; ++l) explicit_tables.push_back(sd::stencil_table(*refinement, size_t(l)));
  auto refiner = osd_input.refine(levels, false);
  // Factory defaults: stencils for every level, each factorized down to the control points.
  std::unique_ptr<const Far::StencilTable> osd_default(Far::StencilTableFactory::Create(*refiner));
  Far::StencilTableFactory::Options last_only;
  last_only.generateIntermediateLevels = false;
  std::unique_ptr<const Far::StencilTable> osd_factorized(Far::StencilTableFactory::Create(*refiner, last_only));
  Far::StencilTableFactory::Options per_level;
  per_level.generateIntermediateLevels = true;
  per_level.factorizeIntermediateLevels = false;
  std::unique_ptr<const Far::StencilTable> osd_per_level(Far::StencilTableFactory::Create(*refiner, per_level));

  std::vector<Vec3> moved = mesh.positions;
  std::vector<Point> osd_moved = osd_base;
  uint64_t state = 42;
  std::vector<std::vector<Vec3>> explicit_levels(explicit_tables.size());
  for (size_t l = 0; l < explicit_tables.size(); ++l) explicit_levels[l].resize(explicit_tables[l].row_count());
  std::vector<Vec3> last_factorized(factorized.row_count());
  std::vector<Point> osd_last(osd_factorized->GetNumStencils());
  // OpenSubdiv level by level: each level's stencils read the previous level, so the table is applied
  // one level range at a time into one buffer holding the control points and then every refined level.
  std::vector<Point> osd_all(osd_moved.size() + size_t(osd_per_level->GetNumStencils()));
  auto osd_level_by_level = [&] {
    std::copy(osd_moved.begin(), osd_moved.end(), osd_all.begin());
    Point* refined = osd_all.data() + osd_moved.size();
    const Point* src = osd_all.data();
    int start = 0;
    for (int l = 1; l <= levels; ++l) {
      const int count = refiner->GetLevel(l).GetNumVertices();
      osd_per_level->UpdateValues(src, refined, start, start + count);
      src = refined + start;
      start += count;
    }
  };
  auto ours_explicit = [&] {
    sd::apply(explicit_tables[0], moved, explicit_levels[0]);
    for (size_t l = 1; l < explicit_tables.size(); ++l)
      sd::apply(explicit_tables[l], explicit_levels[l - 1], explicit_levels[l]);
  };
  auto osd_factorized_update = [&] {
    const Point* src = osd_moved.data();
    Point* dst = osd_last.data();
    osd_factorized->UpdateValues(src, dst);
  };
  Variant b_ours{[&] { sd::evaluate(*refinement, moved, last, scratch); }, {}};
  Variant b_ours_explicit{ours_explicit, {}};
  Variant b_ours_factorized{[&] { sd::apply(factorized, moved, last_factorized); }, {}};
  Variant b_osd_factorized{osd_factorized_update, {}};
  Variant b_osd_per_level{osd_level_by_level, {}};
  std::vector<Point> osd_default_all(size_t(osd_default->GetNumStencils()));
  Variant b_osd_default{[&] {
                          const Point* src = osd_moved.data();
                          Point* dst = osd_default_all.data();
                          osd_default->UpdateValues(src, dst);
                        },
                        {}};
  time_variants(order, repetitions,
                {&b_ours, &b_ours_explicit, &b_ours_factorized, &b_osd_factorized, &b_osd_per_level, &b_osd_default},
                [&] {
                  move_points(moved, state);
                  osd_moved = to_points(moved);
                });

  // The last moved points through every variant, compared with OpenSubdiv's.
  sd::evaluate(*refinement, moved, last, scratch);
  sd::apply(factorized, moved, last_factorized);
  ours_explicit();
  osd_factorized_update();
  osd_level_by_level();
  const Point* osd_per_level_last = osd_all.data() + (osd_all.size() - last.size());
  const std::vector<Vec3> ours_in_osd_numbering = in_osd_numbering(*refinement, last);
  const double b_check =
      std::max({max_difference(ours_in_osd_numbering, osd_last.data()),
                max_difference(ours_in_osd_numbering, osd_per_level_last),
                max_difference(in_osd_numbering(*refinement, last_factorized), osd_last.data()),
                max_difference(in_osd_numbering(*refinement, explicit_levels.back()), osd_last.data())});

  const double b_ours_best = std::min({b_ours.median(), b_ours_explicit.median(), b_ours_factorized.median()});
  const double b_osd_best = std::min(b_osd_factorized.median(), b_osd_per_level.median());
  std::printf("| %s | %d | %u | %.2f | %.2f | **%.2fx** | %.2f | %.2f | **%.2fx** | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | **%.2fx** | %.0e |\n",
              mesh.name.c_str(), levels, refinement->last().vertex_count, a_ours.median(), a_osd.median(),
              a_osd.median() / a_ours.median(), a_ours_full.median(), a_osd_full.median(),
              a_osd_full.median() / a_ours_full.median(), b_ours.median(), b_ours_explicit.median(),
              b_ours_factorized.median(), b_osd_default.median(), b_osd_factorized.median(), b_osd_per_level.median(),
              b_osd_best / b_ours_best, std::max(a_check, b_check));
  const std::string name = mesh.name + ", level " + std::to_string(levels);
  return {{name + ": (a) from scratch, OSD / ours", a_osd.median() / a_ours.median(), kScratchTarget},
          {name + ": (b) points moved, fastest OSD / fastest ours", b_osd_best / b_ours_best, kMovingTarget}};
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args;
  bool write = false;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--write-baseline")
      write = true;
    else
      args.emplace_back(argv[i]);
  }
  const std::string data = args.size() > 0 ? args[0] : FIRE_DATA_DIR;
  const int repetitions = args.size() > 1 ? std::atoi(args[1].c_str()) : 11;
  const std::string order_name = args.size() > 2 ? args[2] : "interleaved";
  if (args.size() > 3 || repetitions < 1 || (order_name != "interleaved" && order_name != "warm")) {
    std::fprintf(stderr, "usage: bench_subdivide [DATA_DIR] [REPETITIONS >= 1] [interleaved|warm] [--write-baseline]\n");
    return 1;
  }
  const std::string baseline_path = FIRE_SOURCE_DIR "/perf/subdivide/baseline.json";
  const auto baseline = fire::perf::read_baseline(baseline_path);
  if (!baseline) {
    std::fprintf(stderr, "bench_subdivide: %s\n", baseline.error().c_str());
    return 1;
  }
  const Order order = order_name == "warm" ? Order::Warm : Order::Interleaved;
  // glibc's adaptive mmap and trim thresholds otherwise make whether a from-scratch build pays page
  // faults depend on what ran before it; keep freed memory for both libraries alike.
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  auto pawn = fire::read_obj(data + "/meshes/pawn.obj");
  if (!pawn) {
    std::fprintf(stderr, "bench_subdivide: %s\n", pawn.error().c_str());
    return 1;
  }
  Mesh control{"pawn control mesh", pawn->positions, pawn->face_offsets, pawn->face_vertices};

  // The pawn's base mesh after one Coons step, as `fire network-from-mesh pawn.obj --unrefine 1 --limit`
  // then `fire reconstruct --method thesis --coons-steps 1` build it (built once, not timed).
  auto network = fire::network_from_mesh(
      {control.positions, control.face_offsets, control.face_vertices, "pawn.obj"}, {.unrefine = 1, .limit = true});
  if (!network) {
    std::fprintf(stderr, "bench_subdivide: %s\n", network.error().c_str());
    return 1;
  }
  fire::reconstruct::ReconstructionState state;
  fire::SurfaceMesh surface;
  const fire::reconstruct::Options thesis{.method = fire::reconstruct::Method::Thesis, .coons_steps = 1};
  if (fire::Status built = fire::reconstruct::reconstruct_update(*network, thesis, state, surface); !built) {
    std::fprintf(stderr, "bench_subdivide: %s\n", built.error.c_str());
    return 1;
  }
  const fire::reconstruct::BaseMesh& base = state.base();
  if (!base.sharp_edges.empty()) {
    std::fprintf(stderr, "bench_subdivide: the pawn's base mesh has sharp edges, which the OpenSubdiv setup omits\n");
    return 1;
  }
  Mesh coons{"pawn after one Coons step", base.positions, base.face_offsets, base.face_vertices};

  std::printf("| base mesh | level | last-level vertices | (a) ours ms | (a) OSD ms | (a) OSD / ours | "
              "(a) ours, full last level ms | (a) OSD, full last level ms | (a) OSD / ours, full | "
              "(b) ours ms | (b) ours, explicit tables ms | (b) ours, factorized ms | (b) OSD default options ms | "
              "(b) OSD last level factorized ms | (b) OSD level by level ms | (b) fastest OSD / fastest ours | "
              "max difference |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::vector<fire::perf::Figure> figures;
  for (const Mesh* mesh : {&control, &coons})
    for (int levels : {3, 4})
      for (fire::perf::Figure& f : run_case(*mesh, levels, repetitions, order)) figures.push_back(std::move(f));
  const fire::perf::BaselineRun run{"bench_subdivide", baseline_path, *baseline, write};
  const std::string command = "bench_subdivide " + std::to_string(repetitions) + " " + order_name;
  if (fire::Status done = fire::perf::finish_baseline_run(run, command, figures); !done) {
    std::fprintf(stderr, "bench_subdivide: %s\n", done.error.c_str());
    return 1;
  }
  return 0;
}
