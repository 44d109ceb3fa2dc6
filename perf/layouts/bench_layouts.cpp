// Memory layouts for polyline points, after thesis section 5.3.5: the six layouts s1..s6 exactly as the thesis
// declares them (meschach VEC for s3..s6), FIRE's point column (fire::Column<Vec3>) and OpenMesh's per-edge
// std::vector property, under sequential and random reads and writes, with and without caching the base pointer
// of the point. The same source is built at -O0 and at -O2 (see CMakeLists.txt); run.sh drives it.
//
// Modes (all print CSV on stdout):
//   points ITERS N1,N2,.. REPEAT   time every layout and operation for each number of points
//   iters N IT1,IT2,.. REPEAT      time every layout and operation for each iteration count
//   once VARIANT N ITERS OP CACHED set up one layout and run one operation once (OP "none": setup only),
//                                  so that cachegrind's counts of two runs can be subtracted
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <random>
#include <string>
#include <vector>

#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

#include "engine/column.hpp"
#include "engine/common.hpp"

extern "C" {
#include <meschach/matrix.h>
}
// meschach defines min and max as macros, which would rewrite std::min and std::max.
#undef min
#undef max

#ifndef FIRE_LAYOUTS_OPT
#error "FIRE_LAYOUTS_OPT must name the optimisation level"
#endif

namespace {

constexpr size_t kMaxPoints = 10'000'000;
// A sample is one pass over a window of the points (sequential: consecutive points; random: consecutive entries
// of one random permutation of all n points) of about this many point operations, so that large sizes and
// iteration counts stay affordable. Successive samples take successive windows, so a sample does not find the
// points of the sample before it in the cache: the misses are those of an n-point structure.
constexpr size_t kSequentialOps = 500'000;
constexpr size_t kRandomOps = 250'000;
// Small structures repeat their pass until a sample holds this many point operations, above the clock's grain.
constexpr size_t kMinOpsPerSample = 500'000;
// Points per OpenMesh edge: about the density of the network in perf/pools.
constexpr size_t kPointsPerEdge = 100;

// The thesis's compile-time arrays, sized for the largest run; a run of n points uses the first n.
double s1[3 * kMaxPoints];
VEC* s3[kMaxPoints];
VEC s5[kMaxPoints];

double* s2 = nullptr;
VEC** s4 = nullptr;
VEC* s6 = nullptr;
double* s5_p = nullptr;
double* s6_p = nullptr;
fire::Column<fire::Vec3> pool;

using OMesh = OpenMesh::PolyMesh_ArrayKernelT<>;
OMesh* om = nullptr;
OpenMesh::EPropHandleT<std::vector<OpenMesh::Vec3d>> om_poly;
size_t om_edges = 0;

// Blocks allocated between the point allocations of the scattered layouts, alive until teardown: the other
// objects a long-running program allocates while it builds its points.
std::vector<void*> junk;

std::vector<uint32_t> perm;  // random order of point indices
std::vector<int> perm_edge;  // the same order as (edge, index in its polyline) for OpenMesh
std::vector<uint32_t> perm_offset;

volatile double sink;

enum class Variant : uint8_t { S1, S2, S3, S4, S5, S6, S3Fresh, S4Fresh, FirePool, OpenMesh, OpenMeshFresh };
constexpr int kVariants = 11;
const char* const kVariantNames[kVariants] = {
    "s1", "s2", "s3", "s4", "s5", "s6", "s3_fresh", "s4_fresh", "fire", "openmesh", "openmesh_fresh"};
enum class Op : uint8_t { SeqRead, SeqWrite, RandRead, RandWrite };
constexpr int kOps = 4;
const char* const kOpNames[kOps] = {"seq_read", "seq_write", "rand_read", "rand_write"};

void junk_between(std::mt19937& rng) {
  junk.push_back(std::malloc(std::uniform_int_distribution<size_t>(16, 128)(rng)));
}

void init_point(double* p, size_t i) {
  p[0] = double(i);
  p[1] = double(i) + 0.5;
  p[2] = double(i) + 0.25;
}

// s5 and s6: n VECs pointing into one malloc'ed double[3n], which `coords` receives.
void point_into(VEC* vecs, double*& coords, size_t n) {
  coords = static_cast<double*>(std::malloc(sizeof(double) * 3 * n));
  for (size_t i = 0; i < n; i++) {
    vecs[i].dim = 3;
    vecs[i].max_dim = 3;
    vecs[i].ve = &coords[i * 3];
    init_point(vecs[i].ve, i);
  }
}

void setup(Variant v, size_t n) {
  std::mt19937 rng(2026);
  switch (v) {
    case Variant::S1:
      for (size_t i = 0; i < n; i++) init_point(&s1[3 * i], i);
      break;
    case Variant::S2:
      s2 = static_cast<double*>(std::malloc(sizeof(double) * 3 * n));
      for (size_t i = 0; i < n; i++) init_point(&s2[3 * i], i);
      break;
    case Variant::S3:
    case Variant::S3Fresh:
      for (size_t i = 0; i < n; i++) {
        s3[i] = v_get(3);
        if (v == Variant::S3) junk_between(rng);
        init_point(s3[i]->ve, i);
      }
      break;
    case Variant::S4:
    case Variant::S4Fresh:
      s4 = static_cast<VEC**>(std::malloc(sizeof(VEC*) * n));
      for (size_t i = 0; i < n; i++) {
        s4[i] = v_get(3);
        if (v == Variant::S4) junk_between(rng);
        init_point(s4[i]->ve, i);
      }
      break;
    case Variant::S5: point_into(s5, s5_p, n); break;
    case Variant::S6:
      s6 = static_cast<VEC*>(std::malloc(sizeof(VEC) * n));
      point_into(s6, s6_p, n);
      break;
    case Variant::FirePool:
      for (size_t i = 0; i < n; i++) {
        double p[3];
        init_point(p, i);
        pool.push_back(fire::Vec3(p[0], p[1], p[2]));
      }
      break;
    case Variant::OpenMesh:
    case Variant::OpenMeshFresh: {
      // A chain of edges, each holding its polyline, grown point by point as a sketch grows it.
      om = new OMesh;
      om->add_property(om_poly, "polyline");
      om_edges = n / kPointsPerEdge;
      std::vector<OpenMesh::VertexHandle> vh;
      for (size_t e = 0; e <= om_edges; e++) vh.push_back(om->add_vertex(OMesh::Point(float(e), 0.f, 0.f)));
      for (size_t e = 0; e < om_edges; e++) {
        const OpenMesh::EdgeHandle eh = om->edge_handle(om->new_edge(vh[e], vh[e + 1]));
        auto& poly = om->property(om_poly, eh);
        for (size_t o = 0; o < kPointsPerEdge; o++) {
          double p[3];
          init_point(p, e * kPointsPerEdge + o);
          poly.push_back(OpenMesh::Vec3d(p[0], p[1], p[2]));
          if (v == Variant::OpenMesh) junk_between(rng);
        }
      }
      break;
    }
  }
}

void teardown(Variant v, size_t n) {
  switch (v) {
    case Variant::S3:
    case Variant::S3Fresh:
      for (size_t i = 0; i < n; i++) v_free(s3[i]);
      break;
    case Variant::S4:
    case Variant::S4Fresh:
      for (size_t i = 0; i < n; i++) v_free(s4[i]);
      std::free(s4);
      break;
    case Variant::S2: std::free(s2); break;
    case Variant::S5: std::free(s5_p); break;
    case Variant::S6:
      std::free(s6);
      std::free(s6_p);
      break;
    case Variant::FirePool: pool = fire::Column<fire::Vec3>(); break;
    case Variant::OpenMesh:
    case Variant::OpenMeshFresh:
      delete om;
      om = nullptr;
      break;
    default: break;
  }
  for (void* b : junk) std::free(b);
  junk.clear();
}

// Address of point i's first coordinate, to report how far apart consecutive points lie.
const double* point_address(Variant v, size_t i) {
  switch (v) {
    case Variant::S3:
    case Variant::S3Fresh: return s3[i]->ve;
    case Variant::S4:
    case Variant::S4Fresh: return s4[i]->ve;
    case Variant::OpenMesh:
    case Variant::OpenMeshFresh:
      return om->property(om_poly, OpenMesh::EdgeHandle(int(i / kPointsPerEdge)))[i % kPointsPerEdge].data();
    default: return nullptr;
  }
}

// The loops are written out per layout, with the thesis's access expressions spelled in place, so that -O0
// executes exactly those expressions; the macros only stamp out the four operations and two caching modes.
// Inside them: i (flat layouts) or e, o (OpenMesh) name the point, k the iteration, t the value written.
#define READ_BODY(X) \
  for (int k = 0; k < iters; k++) acc += X(0) + X(1) + X(2);
#define READ_CACHED_BODY(PTR)                                  \
  {                                                            \
    const double* p = PTR;                                     \
    for (int k = 0; k < iters; k++) acc += p[0] + p[1] + p[2]; \
  }
#define WRITE_BODY(W)               \
  for (int k = 0; k < iters; k++) { \
    const double t = base + k;      \
    W(t)                            \
  }
#define WRITE_CACHED_BODY(PTR)        \
  {                                   \
    double* p = PTR;                  \
    for (int k = 0; k < iters; k++) { \
      const double t = base + k;      \
      p[0] = t;                       \
      p[1] = t + 1.0;                 \
      p[2] = t + 2.0;                 \
    }                                 \
  }
#define FOR_SEQ(...)                           \
  for (size_t i = first; i < first + m; i++) { \
    __VA_ARGS__                                \
  }
#define FOR_RAND(...)                          \
  for (size_t r = first; r < first + m; r++) { \
    const size_t i = perm[r];                  \
    __VA_ARGS__                                \
  }
#define FOR_EDGE_SEQ(...)                                                        \
  for (size_t e = first / kPointsPerEdge; e < (first + m) / kPointsPerEdge; e++) \
    for (size_t o = 0; o < kPointsPerEdge; o++) {                                \
      __VA_ARGS__                                                                \
    }
#define FOR_EDGE_RAND(...)                     \
  for (size_t r = first; r < first + m; r++) { \
    const int e = perm_edge[r];                \
    const size_t o = perm_offset[r];           \
    __VA_ARGS__                                \
  }
// One function per layout: op, cached, window [first, first + m), iterations, value written.
#define LAYOUT_FN(NAME, SEQ, RAND, X, W, PTR)                                       \
  double NAME(Op op, bool cached, size_t first, size_t m, int iters, double base) { \
    double acc = 0;                                                                 \
    switch (op) {                                                                   \
      case Op::SeqRead:                                                                \
        if (cached) SEQ(READ_CACHED_BODY(PTR)) else SEQ(READ_BODY(X)) break;        \
      case Op::SeqWrite:                                                               \
        if (cached) SEQ(WRITE_CACHED_BODY(PTR)) else SEQ(WRITE_BODY(W)) break;      \
      case Op::RandRead:                                                               \
        if (cached) RAND(READ_CACHED_BODY(PTR)) else RAND(READ_BODY(X)) break;      \
      case Op::RandWrite:                                                              \
        if (cached) RAND(WRITE_CACHED_BODY(PTR)) else RAND(WRITE_BODY(W)) break;    \
    }                                                                               \
    return acc;                                                                     \
  }
#define W3(X, t)  \
  X(0) = t;       \
  X(1) = t + 1.0; \
  X(2) = t + 2.0;

#define S1_X(j) s1[3 * i + j]
#define S1_W(t) W3(S1_X, t)
LAYOUT_FN(run_s1, FOR_SEQ, FOR_RAND, S1_X, S1_W, &s1[3 * i])
#define S2_X(j) s2[3 * i + j]
#define S2_W(t) W3(S2_X, t)
LAYOUT_FN(run_s2, FOR_SEQ, FOR_RAND, S2_X, S2_W, &s2[3 * i])
#define S3_X(j) s3[i]->ve[j]
#define S3_W(t) W3(S3_X, t)
LAYOUT_FN(run_s3, FOR_SEQ, FOR_RAND, S3_X, S3_W, s3[i]->ve)
#define S4_X(j) s4[i]->ve[j]
#define S4_W(t) W3(S4_X, t)
LAYOUT_FN(run_s4, FOR_SEQ, FOR_RAND, S4_X, S4_W, s4[i]->ve)
#define S5_X(j) s5[i].ve[j]
#define S5_W(t) W3(S5_X, t)
LAYOUT_FN(run_s5, FOR_SEQ, FOR_RAND, S5_X, S5_W, s5[i].ve)
#define S6_X(j) s6[i].ve[j]
#define S6_W(t) W3(S6_X, t)
LAYOUT_FN(run_s6, FOR_SEQ, FOR_RAND, S6_X, S6_W, s6[i].ve)
// The column hands out const points and takes writes through set(), which keeps the undo journal, so there
// is no writable base pointer to cache: its cached writes are the same set() calls (the tables mark them).
#define FIRE_X(j) pool[i][j]
#define FIRE_W(t) pool.set(i, fire::Vec3(t, t + 1.0, t + 2.0));
double run_fire(Op op, bool cached, size_t first, size_t m, int iters, double base) {
  double acc = 0;
  switch (op) {
    case Op::SeqRead:
      if (cached) FOR_SEQ(READ_CACHED_BODY(pool[i].data())) else FOR_SEQ(READ_BODY(FIRE_X)) break;
    case Op::SeqWrite: FOR_SEQ(WRITE_BODY(FIRE_W)) break;
    case Op::RandRead:
      if (cached) FOR_RAND(READ_CACHED_BODY(pool[i].data())) else FOR_RAND(READ_BODY(FIRE_X)) break;
    case Op::RandWrite: FOR_RAND(WRITE_BODY(FIRE_W)) break;
  }
  return acc;
}
#define OM_X(j) om->property(om_poly, OpenMesh::EdgeHandle(int(e)))[o][j]
#define OM_W(t) W3(OM_X, t)
LAYOUT_FN(run_openmesh, FOR_EDGE_SEQ, FOR_EDGE_RAND, OM_X, OM_W,
          om->property(om_poly, OpenMesh::EdgeHandle(int(e)))[o].data())

double run(Variant v, Op op, bool cached, size_t first, size_t m, int iters, double base) {
  switch (v) {
    case Variant::S1: return run_s1(op, cached, first, m, iters, base);
    case Variant::S2: return run_s2(op, cached, first, m, iters, base);
    case Variant::S3:
    case Variant::S3Fresh: return run_s3(op, cached, first, m, iters, base);
    case Variant::S4:
    case Variant::S4Fresh: return run_s4(op, cached, first, m, iters, base);
    case Variant::S5: return run_s5(op, cached, first, m, iters, base);
    case Variant::S6: return run_s6(op, cached, first, m, iters, base);
    case Variant::FirePool: return run_fire(op, cached, first, m, iters, base);
    case Variant::OpenMesh:
    case Variant::OpenMeshFresh: return run_openmesh(op, cached, first, m, iters, base);
  }
  return 0;
}

// CPU time of this thread, so time spent waiting for a core on the shared machine is not counted.
double thread_s() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

void make_perm(size_t n) {
  perm.resize(n);
  for (size_t i = 0; i < n; i++) perm[i] = uint32_t(i);
  std::mt19937 rng(42);
  std::shuffle(perm.begin(), perm.end(), rng);
  perm_edge.resize(n);
  perm_offset.resize(n);
  for (size_t r = 0; r < n; r++) {
    perm_edge[r] = int(perm[r] / kPointsPerEdge);
    perm_offset[r] = uint32_t(perm[r] % kPointsPerEdge);
  }
}

// Points in a sample's window: about ops / iters, whole OpenMesh edges, at most n.
size_t window(size_t n, Op op, int iters) {
  const size_t ops = op == Op::RandRead || op == Op::RandWrite ? kRandomOps : kSequentialOps;
  const size_t m = ops / size_t(iters) / kPointsPerEdge * kPointsPerEdge;
  return std::clamp<size_t>(m, kPointsPerEdge, n);
}

// Start of the window of the sample-th sample: the windows follow one another and wrap round.
size_t window_start(size_t n, size_t m, size_t sample) {
  const size_t windows = n / m;
  return sample % windows * m;
}

[[noreturn]] void die(const std::string& what) {
  std::fprintf(stderr, "bench_layouts: %s\n", what.c_str());
  std::exit(1);
}

std::vector<long> parse_list(const char* s) {
  std::vector<long> out;
  for (const char* p = s; *p;) {
    char* end = nullptr;
    out.push_back(std::strtol(p, &end, 10));
    if (end == p || out.back() <= 0) die(std::string("bad list ") + s);
    p = *end == ',' ? end + 1 : end;
  }
  return out;
}

// Times every variant and operation at the given (n, iters) pairs, repeat times each, keeping the fastest.
// The repeats go round all operations before repeating, so a burst of load on the machine hits one sample
// of many operations rather than every sample of one.
void sweep(const std::vector<std::pair<size_t, int>>& runs, int repeat) {
  std::printf("kind,opt,variant,op,cached,n,iters,ns_per_op\n");
  size_t last_n = 0;
  for (auto [n, iters] : runs) {
    if (n > kMaxPoints || n % kPointsPerEdge != 0) die("n must be a multiple of 100 up to 10^7");
    if (n != last_n) make_perm(n);
    last_n = n;
    double reference = 0;
    for (int vi = 0; vi < kVariants; vi++) {
      const auto v = static_cast<Variant>(vi);
      setup(v, n);
      const double check = run(v, Op::SeqRead, false, 0, n, 1, 0);
      if (vi == 0) reference = check;
      if (check != reference) die(std::string(kVariantNames[vi]) + " holds other points than s1");
      if (point_address(v, 0) != nullptr) {
        std::vector<double> gaps;
        for (size_t i = 1; i < std::min<size_t>(n, 100'000); i++)
          gaps.push_back(double(reinterpret_cast<uintptr_t>(point_address(v, i))) -
                         double(reinterpret_cast<uintptr_t>(point_address(v, i - 1))));
        std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
        const double contiguous =
            double(std::count_if(gaps.begin(), gaps.end(), [](double g) { return g == 3 * sizeof(double); })) /
            double(gaps.size());
        std::printf("gap,%s,%s,,,%zu,,%.0f;%.3f\n", FIRE_LAYOUTS_OPT, kVariantNames[vi], n, gaps[gaps.size() / 2],
                    contiguous);
      }
      double best[kOps][2];
      for (auto& b : best) b[0] = b[1] = 1e300;
      double base = 0;
      size_t sample = 0;
      for (int r = 0; r < repeat; r++)
        for (int op = 0; op < kOps; op++)
          for (int c = 0; c < 2; c++) {
            const size_t m = window(n, static_cast<Op>(op), iters);
            const size_t first = window_start(n, m, sample++);
            const size_t passes = std::max<size_t>(1, kMinOpsPerSample / (m * size_t(iters)));
            const double t0 = thread_s();
            double acc = 0;
            for (size_t p = 0; p < passes; p++) acc += run(v, static_cast<Op>(op), c == 1, first, m, iters, base += 1);
            const double t = thread_s() - t0;
            sink = acc;
            best[op][c] = std::min(best[op][c], t * 1e9 / double(passes * m * size_t(iters)));
          }
      for (int op = 0; op < kOps; op++)
        for (int c = 0; c < 2; c++) {
          const bool same = v == Variant::FirePool && c == 1 && (static_cast<Op>(op) == Op::SeqWrite || static_cast<Op>(op) == Op::RandWrite);
          std::printf("time,%s,%s,%s,%s,%zu,%d,%.4f\n", FIRE_LAYOUTS_OPT, kVariantNames[vi], kOpNames[op],
                      c ? (same ? "set" : "yes") : "no", n, iters, best[op][c]);
        }
      std::fflush(stdout);
      teardown(v, n);
    }
  }
}

int find(const char* const* names, int count, const char* name) {
  for (int i = 0; i < count; i++)
    if (std::strcmp(names[i], name) == 0) return i;
  die(std::string("unknown name ") + name);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "points" && argc == 5) {
    std::vector<std::pair<size_t, int>> runs;
    for (long n : parse_list(argv[3])) runs.emplace_back(size_t(n), std::atoi(argv[2]));
    sweep(runs, std::atoi(argv[4]));
  } else if (mode == "iters" && argc == 5) {
    std::vector<std::pair<size_t, int>> runs;
    for (long it : parse_list(argv[3])) runs.emplace_back(size_t(std::atol(argv[2])), int(it));
    sweep(runs, std::atoi(argv[4]));
  } else if (mode == "once" && argc == 7) {
    const auto v = static_cast<Variant>(find(kVariantNames, kVariants, argv[2]));
    const size_t n = size_t(std::atol(argv[3]));
    if (n == 0 || n > kMaxPoints || n % kPointsPerEdge != 0) die("n must be a multiple of 100 up to 10^7");
    make_perm(n);
    setup(v, n);
    if (std::strcmp(argv[5], "none") != 0) {
      const auto op = static_cast<Op>(find(kOpNames, kOps, argv[5]));
      const int iters = std::atoi(argv[4]);
      sink = run(v, op, std::strcmp(argv[6], "yes") == 0, 0, window(n, op, iters), iters, 1);
    }
    teardown(v, n);
  } else {
    std::fprintf(stderr,
                 "usage: %s points ITERS N1,N2,.. REPEAT | iters N IT1,IT2,.. REPEAT | "
                 "once VARIANT N ITERS OP|none yes|no\n",
                 argv[0]);
    return 2;
  }
  return 0;
}
