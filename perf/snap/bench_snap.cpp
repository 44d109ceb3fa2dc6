// Snapping index vs nanoflann. For networks of about 10^4, 10^5 and 10^6 polyline points, drawn by
// splitting a square border with curves that rise off the plane like strokes on an object, both hold
// the same points (every live edge's polyline) and answer the same queries:
// - near: a polyline point moved by up to the snap distance; far: anywhere in a box ten times the network's;
// - radius: the nearest point within the snap distance; nearest: the nearest point, unbounded.
// Ours is timed twice: built curve by curve as the person draws (incremental updates after every edit) and
// built in one update (loading). nanoflann: KDTreeSingleIndexAdaptor (static, default leaf size) for queries;
// KDTreeSingleIndexDynamicAdaptor for inserting and deleting one 100-point curve, against SnapIndex::update
// with the curve's edge added to or removed from the mesh. Timings are the thread's CPU time, best of
// several repetitions that interleave the sides compared (the machine is shared).
#include <time.h>

#include <nanoflann.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "engine/mesh.hpp"
#include "engine/snap_index.hpp"
#include "perf/baseline.hpp"
#include "systems/split/edit.hpp"

using namespace fire;

namespace {

constexpr double kSnap = 0.01;  // the sketch system's default snap distance
constexpr uint32_t kQueries = 20000;
constexpr int kRepetitions = 5;
constexpr uint32_t kCurvePoints = 100;
constexpr uint32_t kEdits = 32;  // curves inserted, then deleted, per repetition
constexpr uint64_t kSeed = 2026;
constexpr size_t kSizes[] = {10000, 100000, 1000000};

volatile double g_sink;  // the timed loops' answers go here, so the compiler keeps the loops

double cpu_now() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Each run's best time over the repetitions, the runs taking turns within each repetition, so that a
// change in the machine's load falls on all of them alike.
template <class... F>
std::array<double, sizeof...(F)> best_s(F&&... run) {
  std::array<double, sizeof...(F)> best;
  best.fill(1e300);
  for (int r = 0; r < kRepetitions; ++r) {
    size_t i = 0;
    ((best[i] = std::min(best[i], [&] {
        const double t0 = cpu_now();
        run();
        return cpu_now() - t0;
      }()),
      ++i),
     ...);
  }
  return best;
}

void die(const std::string& why) {
  std::fprintf(stderr, "bench_snap: %s\n", why.c_str());
  std::exit(1);
}

// A stroke from a to b with n points that rises off the plane in a bump with a small ripple.
std::vector<Vec3> stroke(const Vec3& a, const Vec3& b, uint32_t n, double height, double ripple) {
  std::vector<Vec3> out(n);
  for (uint32_t i = 0; i < n; ++i) {
    const double t = double(i) / (n - 1);
    out[i] = (1.0 - t) * a + t * b;
    if (i > 0 && i + 1 < n) out[i].z() += height * std::sin(M_PI * t) + ripple * std::sin(7 * M_PI * t);
  }
  return out;
}

// The side of the square: it grows with the point count so that strokes keep about the same sample
// spacing at every size, as a larger drawing of the same pen would.
double side_for(size_t target) { return std::sqrt(double(target) / 1e4); }

// Splits a square border with strokes between interior points of each chosen face's two longest edges
// until the live polylines hold about `target` points. `index`, when given, follows every edit.
Mesh draw_network(size_t target, SnapIndex* index) {
  Mesh mesh;
  const double s = side_for(target);
  const Vec3 corner[4] = {Vec3(0, 0, 0), Vec3(s, 0, 0), Vec3(s, s, 0), Vec3(0, s, 0)};
  const uint32_t side_points = static_cast<uint32_t>(std::max<size_t>(8, target / 200));
  auto sync = [&] {
    if (!index) return;
    index->sync(mesh);
    mesh.begin_frame(mesh.frame() + 1);
  };
  for (int side = 0; side < 4; ++side) {
    EditCommand c;
    c.kind = side == 0 ? EditKind::StartBorder : side == 3 ? EditKind::CloseBorder : EditKind::AppendBorder;
    c.points = stroke(corner[side], corner[(side + 1) % 4], side_points, 0, 0);
    c.snap_distance = 1e-9;
    if (auto r = execute_edit(mesh, c); !r.ok()) die("border: " + r.error);
    sync();
  }
  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  size_t points = 4 * side_points;
  std::vector<EdgeIndex> edges;
  while (points < target) {
    const FaceIndex f{uint32_t(rng() % mesh.face_slots())};  // splits never remove faces
    edges.clear();
    for (OrientedEdge oe : mesh.face_loop(f)) edges.push_back(edge_of(oe));
    std::sort(edges.begin(), edges.end(), [&](EdgeIndex a, EdgeIndex b) {
      return mesh.edges.point_count[a] != mesh.edges.point_count[b] ? mesh.edges.point_count[a] > mesh.edges.point_count[b] : a < b;
    });
    if (edges.size() < 2 || mesh.edges.point_count[edges[1]] < 5) continue;
    EditCommand c;
    c.kind = EditKind::SplitFace;
    c.face = f;
    auto inner = [&](EdgeIndex e) {
      const uint32_t n = mesh.edges.point_count[e];
      return CurveEnd{e, 1 + uint32_t(rng() % (n - 2))};
    };
    c.start = inner(edges[0]);
    c.end = inner(edges[1]);
    c.points = stroke(mesh.polyline(c.start.edge)[c.start.point], mesh.polyline(c.end.edge)[c.end.point], kCurvePoints,
                      0.05 * unit(rng), 0.002 * unit(rng));
    if (auto r = execute_edit(mesh, c); !r.ok()) die("split: " + r.error);
    sync();
    points += kCurvePoints + 2;  // the curve, and the two points its ends add to the edges they split
  }
  return mesh;
}

// The points as nanoflann reads them: every live polyline, in edge slot order.
struct Cloud {
  std::vector<Vec3> pts;
  size_t kdtree_get_point_count() const { return pts.size(); }
  double kdtree_get_pt(size_t i, size_t d) const { return pts[i][int(d)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

using Static = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud, 3, uint32_t>;
using Dynamic = nanoflann::KDTreeSingleIndexDynamicAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud, 3, uint32_t>;

// The nearest point within a radius, for nanoflann: a result set whose worst distance starts at the radius
// and shrinks to the best found, so its search prunes as ours does.
struct NearestWithin {
  double worst;
  uint32_t index = kNone;
  explicit NearestWithin(double radius) : worst(radius * radius) {}
  bool full() const { return true; }
  size_t size() const { return index == kNone ? 0 : 1; }
  double worstDist() const { return worst; }
  bool addPoint(double d, uint32_t i) {
    if (d <= worst) {
      worst = d;
      index = i;
    }
    return true;
  }
};

template <class Tree>
double nano_query(const Tree& tree, const Vec3& q, double radius) {
  NearestWithin r(radius);
  tree.findNeighbors(r, q.data(), nanoflann::SearchParams());
  return r.index == kNone ? -1 : std::sqrt(r.worst);
}

struct Row {
  const char* name;
  std::vector<Vec3> queries;
  double radius;
};

}  // namespace

int main(int argc, char** argv) {
  const auto baseline = fire::perf::start_baseline_run("bench_snap", FIRE_SOURCE_DIR "/perf/snap/baseline.json", argc, argv);
  if (!baseline) die(baseline.error());
  // nanoflann's time over ours, each row: kept in perf/snap/baseline.json.
  std::vector<fire::perf::Figure> figures;
  std::printf("# bench_snap: snapping index vs nanoflann %d.%d.%d; %u queries per row, insert/delete %u curves of %u points;"
              " best of %d, thread CPU time\n",
              NANOFLANN_VERSION >> 8, (NANOFLANN_VERSION >> 4) & 0xF, NANOFLANN_VERSION & 0xF, kQueries, kEdits, kCurvePoints,
              kRepetitions);
  std::printf("%-8s %-14s %12s %12s %12s %9s %9s\n", "points", "query", "ours inc ns", "ours bulk ns", "nano ns",
              "inc/nano", "bulk/nano");
  for (size_t target : kSizes) {
    SnapIndex incremental;
    const double t_draw = cpu_now();
    Mesh mesh = draw_network(target, &incremental);
    const double draw_s = cpu_now() - t_draw;
    if (auto why = incremental.validate(mesh); !why.empty()) die("incremental index: " + why);
    SnapIndex bulk;
    std::vector<uint32_t> all(mesh.edge_slots());
    for (uint32_t e = 0; e < all.size(); ++e) all[e] = e;
    const double t_bulk = cpu_now();
    bulk.update(mesh, all);
    const double bulk_s = cpu_now() - t_bulk;

    Cloud cloud;
    for (EdgeIndex e{0}; e < mesh.edge_slots(); ++e)
      if (mesh.edge_alive(e)) cloud.pts.insert(cloud.pts.end(), mesh.polyline(e).begin(), mesh.polyline(e).end());
    const double t_nano = cpu_now();
    Static tree(3, cloud);
    const double nano_build_s = cpu_now() - t_nano;
    const size_t n = cloud.pts.size();

    const double side = side_for(target);
    std::mt19937_64 rng(kSeed + target);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    Row rows[4] = {{"near radius", {}, kSnap}, {"near nearest", {}, SnapIndex::kUnbounded},
                   {"far radius", {}, kSnap}, {"far nearest", {}, SnapIndex::kUnbounded}};
    for (uint32_t i = 0; i < kQueries; ++i) {
      const Vec3 near = cloud.pts[rng() % n] + kSnap * Vec3(unit(rng), unit(rng), unit(rng));
      const Vec3 far = side * (Vec3(0.5, 0.5, 0) + 5.0 * Vec3(unit(rng), unit(rng), unit(rng)));
      rows[0].queries.push_back(near);
      rows[1].queries.push_back(near);
      rows[2].queries.push_back(far);
      rows[3].queries.push_back(far);
    }
    std::printf("# %zu points, %zu edges; drawn with incremental sync in %.2f s; bulk index %.1f ms, nanoflann static %.1f ms;"
                " tree height %u incremental, %u bulk\n",
                n, mesh.edge_count(), draw_s, 1e3 * bulk_s, 1e3 * nano_build_s, incremental.height(),
                bulk.height());
    for (const Row& row : rows) {
      // The same answers first (distances: equally near points may differ in which one is named).
      size_t mismatches = 0;
      for (const Vec3& q : row.queries) {
        const SnapHit a = incremental.nearest(q, row.radius), b = bulk.nearest(q, row.radius);
        const double c = nano_query(tree, q, row.radius);
        if (!(a == b) || (a.found() ? std::abs(a.distance - c) > 1e-12 : c >= 0)) ++mismatches;
      }
      if (mismatches) die(std::string(row.name) + ": " + std::to_string(mismatches) + " answers differ from nanoflann's");
      double sink = 0;
      auto ours = [&](const SnapIndex& index) {
        return [&, at = &index] {
          for (const Vec3& q : row.queries) sink += at->nearest(q, row.radius).distance;
          g_sink = sink;
        };
      };
      const auto [inc, blk, nano] = best_s(ours(incremental), ours(bulk), [&] {
        for (const Vec3& q : row.queries) sink += nano_query(tree, q, row.radius);
        g_sink = sink;
      });
      const double per = 1e9 / double(row.queries.size());
      std::printf("%-8zu %-14s %12.1f %12.1f %12.1f %9.2f %9.2f\n", n, row.name, inc * per, blk * per, nano * per,
                  inc / nano, blk / nano);
      figures.push_back({std::to_string(target) + " points, " + row.name + ": nanoflann / ours (incremental)", nano / inc, 0});
    }

    // Insert and delete one curve at a time: ours through the mesh and update(), nanoflann's dynamic index
    // through addPoints / removePoint on the same points appended to its cloud.
    std::vector<std::vector<Vec3>> curves;
    for (uint32_t k = 0; k < kEdits; ++k) {
      const Vec3 a(0.5 + 0.4 * unit(rng), 0.5 + 0.4 * unit(rng), 0), b = a + Vec3(0.1 * unit(rng), 0.1 * unit(rng), 0);
      curves.push_back(stroke(side * a, side * b, kCurvePoints, 0.05, 0.002));
    }
    double ours_insert = 1e300, ours_delete = 1e300, nano_insert = 1e300, nano_delete = 1e300;
    for (int r = 0; r < kRepetitions; ++r) {
      std::vector<EdgeIndex> added;
      double t = 0;
      for (const auto& c : curves) {
        const VertexIndex v0 = mesh.add_vertex(c.front()), v1 = mesh.add_vertex(c.back());
        const EdgeIndex e = mesh.add_edge(v0, v1, c);
        const uint32_t slot[1] = {e};
        const double t0 = cpu_now();
        bulk.update(mesh, slot);
        t += cpu_now() - t0;
        added.push_back(e);
      }
      ours_insert = std::min(ours_insert, t / kEdits);
      t = 0;
      for (EdgeIndex e : added) {
        const VertexIndex v0{mesh.edges.vertex[e][0]}, v1{mesh.edges.vertex[e][1]};
        mesh.remove_edge(e);
        mesh.remove_vertex(v0);
        mesh.remove_vertex(v1);
        const uint32_t slot[1] = {e};
        const double t0 = cpu_now();
        bulk.update(mesh, slot);
        t += cpu_now() - t0;
      }
      ours_delete = std::min(ours_delete, t / kEdits);

      Cloud dyn_cloud{cloud.pts};
      Dynamic dyn(3, dyn_cloud);
      t = 0;
      std::vector<uint32_t> first;
      for (const auto& c : curves) {
        const uint32_t at = uint32_t(dyn_cloud.pts.size());
        dyn_cloud.pts.insert(dyn_cloud.pts.end(), c.begin(), c.end());
        const double t0 = cpu_now();
        dyn.addPoints(at, at + kCurvePoints - 1);
        t += cpu_now() - t0;
        first.push_back(at);
      }
      nano_insert = std::min(nano_insert, t / kEdits);
      t = 0;
      for (uint32_t at : first) {
        const double t0 = cpu_now();
        for (uint32_t i = 0; i < kCurvePoints; ++i) dyn.removePoint(at + i);
        t += cpu_now() - t0;
      }
      nano_delete = std::min(nano_delete, t / kEdits);
    }
    if (auto why = bulk.validate(mesh); !why.empty()) die("index after the edits: " + why);
    std::printf("%-8zu %-14s %12.2f %12s %12.2f %9.3f   (microseconds per curve, ours vs dynamic index)\n", n,
                "insert curve", 1e6 * ours_insert, "", 1e6 * nano_insert, ours_insert / nano_insert);
    std::printf("%-8zu %-14s %12.2f %12s %12.2f %9.3f\n", n, "delete curve", 1e6 * ours_delete, "", 1e6 * nano_delete,
                ours_delete / nano_delete);
    figures.push_back({std::to_string(target) + " points, insert curve: nanoflann dynamic / ours", nano_insert / ours_insert, 0});
    figures.push_back({std::to_string(target) + " points, delete curve: nanoflann dynamic / ours", nano_delete / ours_delete, 0});
  }
  if (fire::Status done = fire::perf::finish_baseline_run(*baseline, "bench_snap", figures); !done) die(done.error);
  return 0;
}
