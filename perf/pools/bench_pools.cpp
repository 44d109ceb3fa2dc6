// Pools vs OpenMesh: builds a curve network of about 100,000 polyline points and 1,000 faces by
// splitting (a square border, then 999 straight curves between interior points of two edges of a
// random face), reads every point sequentially and in a shuffled order, and prints the memory per
// element and the timings (medians) of our pools next to OpenMesh's PolyMesh_ArrayKernelT (default
// traits) holding the same vertices, faces and edges, with each edge's polyline as a custom edge
// property std::vector<Vec3d>.
#include <malloc.h>
#include <time.h>

#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "engine/mesh.hpp"
#include "perf/baseline.hpp"
#include "systems/split/edit.hpp"

using namespace fire;

namespace {

using OMesh = OpenMesh::PolyMesh_ArrayKernelT<>;  // default traits: float points, prev half-edges, no status

constexpr uint32_t kFaces = 1000;
constexpr uint32_t kBorderPoints = 100;  // per side of the square
constexpr uint32_t kCurvePoints = 98;    // per splitting curve: about 100,000 points in all
constexpr int kRepetitions = 21;
constexpr uint64_t kSeed = 2026;

// Timings are the thread's CPU time, not wall time: the benchmark VM is shared, and time spent waiting
// for a core is not the code's.
double cpu_now() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double median(std::vector<double> t) {
  std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
  return t[t.size() / 2];
}

template <class F>
double median_s(F&& run) {
  std::vector<double> t;
  for (int r = 0; r < kRepetitions; ++r) {
    const double t0 = cpu_now();
    run();
    t.push_back(cpu_now() - t0);
  }
  return median(t);
}

std::vector<Vec3> straight(const Vec3& a, const Vec3& b, uint32_t n) {
  std::vector<Vec3> out(n);
  for (uint32_t i = 0; i < n; ++i) {
    const double t = double(i) / (n - 1);
    out[i] = (1.0 - t) * a + t * b;
  }
  return out;
}

void die(const std::string& why) {
  std::fprintf(stderr, "bench_pools: %s\n", why.c_str());
  std::exit(1);
}

// The network, built through the editing API as a person would draw it. With `history` the edits go
// through EditHistory (undo journal on); without, through execute_edit. `seconds`: the time of the edits.
Mesh build_by_splitting(bool history, double& seconds) {
  const double t0 = cpu_now();
  Mesh mesh;
  EditHistory undo;
  auto apply = [&](const EditCommand& c) { return history ? undo.apply(mesh, c) : execute_edit(mesh, c); };
  const Vec3 corner[4] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  for (int side = 0; side < 4; ++side) {
    EditCommand c;
    c.kind = side == 0 ? EditKind::StartBorder : side == 3 ? EditKind::CloseBorder : EditKind::AppendBorder;
    c.points = straight(corner[side], corner[(side + 1) % 4], kBorderPoints);
    c.snap_distance = 1e-9;
    if (auto r = apply(c); !r.ok()) die("border: " + r.error);
  }
  // Faces are convex (the square cut by straight chords), so every chord stays inside its face. Ends
  // are interior points of the face's two longest polylines: no 2-gons or doubled edges, which OpenMesh
  // cannot hold.
  std::mt19937_64 rng(kSeed);
  std::vector<FaceIndex> alive;
  while (mesh.face_count() < kFaces) {
    alive.clear();
    for (FaceIndex f{0}; f < mesh.face_slots(); ++f)
      if (mesh.face_alive(f)) alive.push_back(f);
    const FaceIndex f = alive[rng() % alive.size()];
    std::vector<EdgeIndex> edges;
    for (OrientedEdge oe : mesh.face_loop(f)) edges.push_back(edge_of(oe));
    std::sort(edges.begin(), edges.end(), [&](EdgeIndex a, EdgeIndex b) {
      return mesh.edges.point_count[a] != mesh.edges.point_count[b] ? mesh.edges.point_count[a] > mesh.edges.point_count[b] : a < b;
    });
    if (edges.size() < 2 || mesh.edges.point_count[edges[1]] < 3) continue;
    EditCommand c;
    c.kind = EditKind::SplitFace;
    c.face = f;
    c.start = {edges[0], mesh.edges.point_count[edges[0]] / 2};
    c.end = {edges[1], mesh.edges.point_count[edges[1]] / 2};
    c.points = straight(mesh.polyline(edges[0])[c.start.point], mesh.polyline(edges[1])[c.end.point], kCurvePoints);
    if (auto r = apply(c); !r.ok()) die("split: " + r.error);
  }
  seconds = cpu_now() - t0;
  if (auto why = mesh.validate(); !why.empty()) die("invalid network: " + why);
  return mesh;
}

size_t heap_in_use() { return mallinfo2().uordblks; }

struct Layout {  // bytes per element of each pool, from the column element types
  size_t vertex, edge, face, face_edge, point, free_slot, stamp;
};

Layout our_layout(const Mesh& m) {
  Layout l;
  l.vertex = sizeof(m.vertices.position[0]) + sizeof(m.vertices.first_edge[0]) + sizeof(m.vertices.generation[0]) +
             sizeof(m.vertices.flags[0]);
  l.edge = sizeof(m.edges.vertex[0]) + sizeof(m.edges.face[0]) + sizeof(m.edges.next[0]) + sizeof(m.edges.point_offset[0]) +
           sizeof(m.edges.point_count[0]) + sizeof(m.edges.generation[0]) + sizeof(m.edges.flags[0]);
  l.face = sizeof(m.faces.edge_offset[0]) + sizeof(m.faces.edge_count[0]) + sizeof(m.faces.generation[0]) + sizeof(m.faces.flags[0]);
  l.face_edge = sizeof(m.face_edges[0]);
  l.point = sizeof(m.points[0]);
  l.free_slot = sizeof(m.vertices.free_list[0]);
  l.stamp = sizeof(m.vertices.changes.stamp[0]);
  return l;
}

}  // namespace

int main(int argc, char** argv) {
  const auto baseline = fire::perf::start_baseline_run("bench_pools", FIRE_SOURCE_DIR "/perf/pools/baseline.json", argc, argv);
  if (!baseline) die(baseline.error());
  std::printf("# bench_pools: %u faces by splitting, curves of %u points, medians of %d runs\n", kFaces, kCurvePoints, kRepetitions);

  // ---- build by splitting
  std::vector<double> plain, journaled;
  for (int r = 0; r < kRepetitions; ++r) {
    double s = 0;
    (void)build_by_splitting(false, s);
    plain.push_back(s);
    (void)build_by_splitting(true, s);
    journaled.push_back(s);
  }
  double unused = 0;
  const Mesh built = build_by_splitting(false, unused);
  const double t_build = median(plain), t_build_history = median(journaled);
  const size_t slots_v = built.vertex_slots(), slots_e = built.edge_slots(), slots_f = built.face_slots();
  const size_t before_points = built.points.size(), before_face_edges = built.face_edges.size();
  const size_t bytes_before = built.pool_bytes();
  Mesh mesh = built;
  const double t_compact = median_s([&] {
    Mesh copy = built;
    copy.compact();
  });
  mesh.compact();
  const size_t nv = mesh.vertex_count(), ne = mesh.edge_count(), nf = mesh.face_count();
  const size_t np = mesh.points.size(), nfe = mesh.face_edges.size();
  if (np != mesh.live_point_count()) die("compacted point pool holds dead points");

  // ---- the same network in OpenMesh
  std::vector<OMesh::VertexHandle> vh(nv);
  std::vector<OMesh::EdgeHandle> eh(ne);
  std::vector<OMesh::VertexHandle> corners;
  corners.reserve(ne);
  const size_t heap0 = heap_in_use();  // from here on, only OpenMesh allocates
  const double t_om0 = cpu_now();
  OMesh om;
  OpenMesh::EPropHandleT<std::vector<OpenMesh::Vec3d>> polyline;
  om.add_property(polyline, "polyline");
  for (uint32_t v = 0; v < nv; ++v) {
    const Vec3& p = mesh.vertices.position[v];
    vh[v] = om.add_vertex(OMesh::Point(float(p.x()), float(p.y()), float(p.z())));
  }
  for (FaceIndex f{0}; f < nf; ++f) {
    corners.clear();
    for (OrientedEdge oe : mesh.face_loop(f)) corners.push_back(vh[mesh.tail(oe)]);
    if (!om.add_face(corners).is_valid()) die("OpenMesh refused face " + std::to_string(f));
  }
  for (EdgeIndex e{0}; e < ne; ++e) {
    auto h = om.find_halfedge(vh[mesh.edges.vertex[e][0]], vh[mesh.edges.vertex[e][1]]);
    if (!h.is_valid()) die("OpenMesh has no edge for edge " + std::to_string(e));
    eh[e] = om.edge_handle(h);
    auto line = mesh.polyline(e);
    auto& dst = om.property(polyline, eh[e]);
    dst.reserve(line.size());
    for (const Vec3& p : line) dst.emplace_back(p.x(), p.y(), p.z());
  }
  const double t_om_build = cpu_now() - t_om0;
  const size_t om_heap = heap_in_use() - heap0;
  if (om.n_vertices() != nv || om.n_edges() != ne || om.n_faces() != nf) die("OpenMesh counts differ");

  // ---- reading every point
  std::vector<uint32_t> order(np);
  std::iota(order.begin(), order.end(), 0u);
  std::shuffle(order.begin(), order.end(), std::mt19937_64(kSeed));
  // OpenMesh's equivalent of a global point index: (edge, index in its polyline), shuffled the same way.
  std::vector<std::pair<OMesh::EdgeHandle, uint32_t>> om_point_at(np);
  for (uint32_t e = 0; e < ne; ++e)
    for (uint32_t i = 0; i < mesh.edges.point_count[e]; ++i) om_point_at[mesh.edges.point_offset[e] + i] = {eh[e], i};
  std::vector<std::pair<OMesh::EdgeHandle, uint32_t>> om_order(np);
  for (size_t k = 0; k < np; ++k) om_order[k] = om_point_at[order[k]];

  // Three sums, one per coordinate: independent add chains, so the loops wait on memory rather than on
  // one chain of floating-point additions.
  struct Sum {
    double x = 0, y = 0, z = 0;
    double total() const { return x + y + z; }
  };
  double sum_pool = 0, sum_edges = 0, sum_random = 0, sum_om_edges = 0, sum_om_random = 0;
  const double t_pool = median_s([&] {
    Sum s;
    for (const Vec3& p : mesh.points.values()) s.x += p.x(), s.y += p.y(), s.z += p.z();
    sum_pool = s.total();
  });
  const double t_edges = median_s([&] {
    Sum s;
    for (EdgeIndex e{0}; e < mesh.edge_slots(); ++e)
      for (const Vec3& p : mesh.polyline(e)) s.x += p.x(), s.y += p.y(), s.z += p.z();
    sum_edges = s.total();
  });
  const double t_random = median_s([&] {
    Sum s;
    const Vec3* pts = mesh.points.values().data();
    for (uint32_t i : order) s.x += pts[i].x(), s.y += pts[i].y(), s.z += pts[i].z();
    sum_random = s.total();
  });
  const double t_om_edges = median_s([&] {
    Sum s;
    for (auto e : om.edges())
      for (const auto& p : om.property(polyline, e)) s.x += p[0], s.y += p[1], s.z += p[2];
    sum_om_edges = s.total();
  });
  const double t_om_random = median_s([&] {
    Sum s;
    for (const auto& [e, i] : om_order) {
      const auto& p = om.property(polyline, e)[i];
      s.x += p[0], s.y += p[1], s.z += p[2];
    }
    sum_om_random = s.total();
  });
  // Same points read: the shuffled sums add the same numbers in the same order.
  if (sum_random != sum_om_random) die("shuffled sums differ between the pools and OpenMesh");
  if (std::abs(sum_pool - sum_om_edges) > 1e-9 * std::abs(sum_pool) || std::abs(sum_edges - sum_pool) > 1e-9 * std::abs(sum_pool))
    die("sequential sums differ");

  // ---- memory
  const Layout l = our_layout(mesh);
  const size_t layout_total = nv * l.vertex + ne * l.edge + nf * l.face + nfe * l.face_edge + np * l.point;
  const size_t om_vertex = sizeof(OpenMesh::ArrayItems::Vertex) + sizeof(OMesh::Point);
  const size_t om_edge = sizeof(OpenMesh::ArrayItems::Edge);
  const size_t om_face = sizeof(OpenMesh::ArrayItems::Face);
  const size_t om_edge_prop = sizeof(std::vector<OpenMesh::Vec3d>);
  const size_t om_point = sizeof(OpenMesh::Vec3d);
  const size_t om_layout_total = nv * om_vertex + ne * (om_edge + om_edge_prop) + nf * om_face + np * om_point;

  std::printf("network: %zu vertices, %zu edges, %zu faces, %zu polyline points (%zu face-edge entries)\n", nv, ne, nf, np, nfe);
  std::printf("before compaction: %zu/%zu/%zu vertex/edge/face slots, %zu points, %zu face-edge entries, pool_bytes %zu\n",
              slots_v, slots_e, slots_f, before_points, before_face_edges, bytes_before);
  std::printf("\nbytes per element (layout: sum of the column element sizes; OpenMesh: item + standard property sizes)\n");
  std::printf("| element | FIRE pools | OpenMesh |\n|---|---|---|\n");
  std::printf("| vertex | %zu (position 24, first_edge 4, generation 4, flags 1) | %zu (item 4, float point 12) |\n", l.vertex, om_vertex);
  std::printf("| edge | %zu (vertex 8, face 8, next 8, point offset 4, count 4, generation 4, flags 1) | %zu (2 half-edges of 16) + %zu (std::vector header) |\n",
              l.edge, om_edge, om_edge_prop);
  std::printf("| face | %zu (edge offset 4, count 4, generation 4, flags 1) + %zu per edge in its loop (%.2f mean) | %zu (item 4) |\n",
              l.face, l.face_edge, double(nfe) / double(nf), om_face);
  std::printf("| point | %zu | %zu in the edge's heap block |\n", l.point, om_point);
  std::printf("(FIRE also keeps a %zu-byte change stamp per vertex, edge and face and %zu bytes per dead slot on a free list, none after compaction)\n",
              l.stamp, l.free_slot);
  std::printf("\ntotal bytes: FIRE layout %zu, FIRE pool_bytes() after compaction %zu (%.2f per point); "
              "OpenMesh layout %zu, OpenMesh heap measured (mallinfo2) %zu (%.2f per point)\n",
              layout_total, mesh.pool_bytes(), double(mesh.pool_bytes()) / double(np), om_layout_total, om_heap,
              double(om_heap) / double(np));
  std::printf("\ntimings (thread CPU time, median of %d)\n", kRepetitions);
  std::printf("| operation | FIRE pools | OpenMesh |\n|---|---|---|\n");
  std::printf("| build by splitting (execute_edit, 4 border + %zu splits) | %.2f ms | - |\n", size_t(kFaces - 1), t_build * 1e3);
  std::printf("| build by splitting through EditHistory (undo journal on) | %.2f ms | - |\n", t_build_history * 1e3);
  std::printf("| compact() | %.2f ms | - |\n", t_compact * 1e3);
  std::printf("| build from the final topology + copy polylines (once) | - | %.2f ms |\n", t_om_build * 1e3);
  std::printf("| read all points: point pool in order | %.1f us (%.2f ns/point) | - |\n", t_pool * 1e6, t_pool * 1e9 / double(np));
  std::printf("| read all points: edge by edge | %.1f us (%.2f ns/point) | %.1f us (%.2f ns/point) |\n", t_edges * 1e6,
              t_edges * 1e9 / double(np), t_om_edges * 1e6, t_om_edges * 1e9 / double(np));
  std::printf("| read all points: shuffled order | %.1f us (%.2f ns/point) | %.1f us (%.2f ns/point) |\n", t_random * 1e6,
              t_random * 1e9 / double(np), t_om_random * 1e6, t_om_random * 1e9 / double(np));
  std::printf("checksums: %.17g %.17g %.17g %.17g %.17g\n", sum_pool, sum_edges, sum_random, sum_om_edges, sum_om_random);
  // OpenMesh over FIRE, each kept in perf/pools/baseline.json.
  const std::vector<fire::perf::Figure> figures = {
      {"heap bytes per point: OpenMesh / FIRE after compaction", double(om_heap) / double(mesh.pool_bytes()), 0},
      {"read all points edge by edge: OpenMesh / FIRE", t_om_edges / t_edges, 0},
      {"read all points in shuffled order: OpenMesh / FIRE", t_om_random / t_random, 0}};
  if (fire::Status done = fire::perf::finish_baseline_run(*baseline, "bench_pools", figures); !done) die(done.error);
  return 0;
}
