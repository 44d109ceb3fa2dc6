// Surface distances: closest points against brute force, the BVH against a linear scan, analytic
// two-sided distances, a surface against itself, and the reference limit surface's refusals.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>
#include <unistd.h>

#include "platform/obj.hpp"
#include "platform/surface_io.hpp"
#include "systems/evaluate/evaluate.hpp"

using namespace fire;
using namespace fire::evaluate;
using Catch::Matchers::Contains;

namespace {

const std::string kMeshes = std::string(FIRE_DATA_DIR) + "/meshes/";

// An independent closest point: the projection onto the plane when it falls inside (signed areas),
// else the nearest of the three edges.
Vec3 brute_closest(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  auto on_segment = [&](const Vec3& s, const Vec3& t) {
    const double len2 = (t - s).squaredNorm();
    double u = len2 > 0 ? (p - s).dot(t - s) / len2 : 0;
    u = u < 0 ? 0 : (u > 1 ? 1 : u);
    return Vec3(s + u * (t - s));
  };
  std::vector<Vec3> candidates = {on_segment(a, b), on_segment(b, c), on_segment(c, a)};
  const Vec3 n = (b - a).cross(c - a);
  if (n.squaredNorm() > 0) {
    const Vec3 q = p - n * ((p - a).dot(n) / n.squaredNorm());
    if ((b - a).cross(q - a).dot(n) >= 0 && (c - b).cross(q - b).dot(n) >= 0 && (a - c).cross(q - c).dot(n) >= 0)
      candidates.push_back(q);
  }
  Vec3 best = candidates[0];
  for (const Vec3& q : candidates)
    if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
  return best;
}

TriangleMesh square(double z, double width = 1) {
  TriangleMesh m;
  m.positions = {{0, 0, z}, {width, 0, z}, {width, 1, z}, {0, 1, z}};
  m.triangles = {0, 1, 2, 0, 2, 3};
  return m;
}

TriangleMesh triangulated_obj(const std::string& name) {
  auto obj = read_obj(kMeshes + name);
  REQUIRE(obj.ok());
  auto mesh = triangulate(obj->positions, obj->face_offsets, obj->face_vertices);
  REQUIRE(mesh.ok());
  return *mesh;
}

Result<TriangleMesh> reference_of(const std::string& name, int levels) {
  auto obj = read_obj(kMeshes + name);
  REQUIRE(obj.ok());
  return reference_limit_surface(obj->positions, obj->face_offsets, obj->face_vertices, levels);
}

}  // namespace

TEST_CASE("closest point on a triangle in each of the seven Voronoi regions", "[evaluate][closest]") {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  struct Case {
    const char* region;
    Vec3 p, expected;
  };
  const Case cases[] = {
      {"vertex a", {-1, -1, 0.3}, a},
      {"vertex b", {2, -0.5, 0.2}, b},
      {"vertex c", {-0.5, 2, -0.4}, c},
      {"edge ab", {0.5, -1, 0.5}, {0.5, 0, 0}},
      {"edge ac", {-1, 0.5, 0.1}, {0, 0.5, 0}},
      {"edge bc", {1, 1, 0.2}, {0.5, 0.5, 0}},
      {"face", {0.2, 0.3, 0.7}, {0.2, 0.3, 0}},
  };
  for (const Case& k : cases) {
    INFO(k.region);
    CHECK((closest_point_on_triangle(k.p, a, b, c) - k.expected).norm() < 1e-15);
    CHECK((brute_closest(k.p, a, b, c) - k.expected).norm() < 1e-15);
    // The corner order must not matter.
    CHECK((closest_point_on_triangle(k.p, c, a, b) - k.expected).norm() < 1e-15);
  }
}

TEST_CASE("closest point on random triangles agrees with brute force", "[evaluate][closest]") {
  std::mt19937_64 rng(12345);
  std::normal_distribution<double> g(0, 1);
  auto random_point = [&] { return Vec3(g(rng), g(rng), g(rng)); };
  int regions_seen[7] = {0};
  for (int i = 0; i < 20000; ++i) {
    const Vec3 a = random_point(), b = random_point(), c = random_point(), p = 2 * random_point();
    const Vec3 q = closest_point_on_triangle(p, a, b, c);
    const Vec3 r = brute_closest(p, a, b, c);
    REQUIRE((q - p).norm() == Approx((r - p).norm()).margin(1e-12));
    REQUIRE((q - r).norm() < 1e-9);
    // Which region: count how many barycentric coordinates are zero.
    const Eigen::Matrix<double, 3, 2> e = (Eigen::Matrix<double, 3, 2>() << b - a, c - a).finished();
    const Eigen::Vector2d uv = e.colPivHouseholderQr().solve(q - a);
    const int zeros = (std::abs(uv[0]) < 1e-12) + (std::abs(uv[1]) < 1e-12) + (std::abs(1 - uv[0] - uv[1]) < 1e-12);
    ++regions_seen[zeros];
  }
  CHECK(regions_seen[0] > 100);  // face
  CHECK(regions_seen[1] > 100);  // edges
  CHECK(regions_seen[2] > 100);  // vertices
}

TEST_CASE("degenerate triangles are their edges", "[evaluate][closest]") {
  const Vec3 p(0.3, 1, 0.2);
  const Vec3 q = closest_point_on_triangle(p, {0, 0, 0}, {1, 0, 0}, {2, 0, 0});  // collinear
  CHECK((q - Vec3(0.3, 0, 0)).norm() < 1e-15);
  const Vec3 r = closest_point_on_triangle(p, {1, 1, 1}, {1, 1, 1}, {1, 1, 1});  // one point
  CHECK(r == Vec3(1, 1, 1));
  const Vec3 s = closest_point_on_triangle(p, {0, 0, 0}, {0, 0, 0}, {0, 2, 0});  // two corners equal
  CHECK((s - Vec3(0, 1, 0)).norm() < 1e-15);
}

TEST_CASE("BVH closest points equal a linear scan over every triangle", "[evaluate][bvh]") {
  const TriangleMesh mesh = triangulated_obj("pawn.obj");
  const TriangleBvh bvh(mesh);
  CHECK(bvh.node_count() > 100);
  std::mt19937_64 rng(7);
  Vec3 lo = mesh.positions[0], hi = lo;
  for (const Vec3& p : mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  std::uniform_real_distribution<double> u(-0.2, 1.2);
  std::uniform_int_distribution<uint32_t> any_triangle(0, static_cast<uint32_t>(mesh.triangle_count() - 1));
  for (int i = 0; i < 500; ++i) {
    const Vec3 p = lo + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(hi - lo);
    double best = std::numeric_limits<double>::infinity();
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
      const Vec3 q = closest_point_on_triangle(p, mesh.positions[mesh.triangles[3 * t]],
                                               mesh.positions[mesh.triangles[3 * t + 1]],
                                               mesh.positions[mesh.triangles[3 * t + 2]]);
      best = std::min(best, (q - p).squaredNorm());
    }
    const TriangleBvh::Hit hit = bvh.closest(p);
    // Equal up to the last bit of a point on an edge two triangles share, computed from either side.
    REQUIRE(hit.distance_squared == Approx(best).epsilon(1e-13));
    REQUIRE((hit.point - p).squaredNorm() == Approx(best).epsilon(1e-13));
    REQUIRE(bvh.closest(p, any_triangle(rng)).distance_squared == Approx(best).epsilon(1e-13));  // any hint
  }
}

TEST_CASE("BVH ray casts equal a linear scan over every triangle", "[evaluate][bvh][ray]") {
  const TriangleMesh mesh = triangulated_obj("pawn.obj");
  const TriangleBvh bvh(mesh);
  Vec3 lo = mesh.positions[0], hi = lo;
  for (const Vec3& p : mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-0.5, 1.5), n(-1.0, 1.0);
  int hits = 0;
  for (int i = 0; i < 1000; ++i) {
    // From outside or inside the box, towards a point inside it; every tenth ray along an axis.
    const Vec3 origin = lo + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(hi - lo);
    const Vec3 target = lo + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(hi - lo) * 0.5 + (hi - lo) * 0.25;
    Vec3 direction = (target - origin).normalized();
    if (i % 10 == 0) direction = Vec3::Unit(i / 10 % 3) * (n(rng) < 0 ? -1.0 : 1.0);
    double best = std::numeric_limits<double>::infinity();
    uint32_t best_triangle = kNoTriangle;
    for (uint32_t t = 0; t < mesh.triangle_count(); ++t) {
      const Vec3 a = mesh.positions[mesh.triangles[3 * t]], b = mesh.positions[mesh.triangles[3 * t + 1]],
                 c = mesh.positions[mesh.triangles[3 * t + 2]];
      // The plane's parameter, then the point inside the triangle by its barycentric coordinates.
      const Vec3 normal = (b - a).cross(c - a);
      const double along = normal.dot(direction);
      if (along == 0) continue;
      const double t_hit = normal.dot(a - origin) / along;
      if (!(t_hit > 0)) continue;
      const Vec3 p = origin + t_hit * direction;
      const double area = normal.squaredNorm();
      const double wa = normal.dot((b - p).cross(c - p)) / area, wb = normal.dot((c - p).cross(a - p)) / area;
      if (wa < -1e-12 || wb < -1e-12 || 1 - wa - wb < -1e-12) continue;
      if (t_hit < best - 1e-12) {
        best = t_hit;
        best_triangle = t;
      }
    }
    const TriangleBvh::Hit hit = bvh.ray_cast(origin, direction);
    if (best_triangle == kNoTriangle) {
      REQUIRE(hit.triangle == kNoTriangle);
      continue;
    }
    ++hits;
    REQUIRE(hit.triangle != kNoTriangle);
    REQUIRE(std::sqrt(hit.distance_squared) == Approx(best).epsilon(1e-9));
    REQUIRE((hit.point - (origin + best * direction)).norm() < 1e-9 * (hi - lo).norm());
  }
  CHECK(hits > 300);  // the test would be empty if the rays missed
  CHECK(bvh.ray_cast(hi + (hi - lo), (hi - lo).normalized()).triangle == kNoTriangle);  // pointing away
}

TEST_CASE("a square against itself moved 0.1 along its normal", "[evaluate][analytic]") {
  const TriangleMesh a = square(0), b = square(0.1);
  const TriangleBvh a_bvh(a), b_bvh(b);
  const double diagonal = bounding_box_diagonal(b.positions);
  CHECK(diagonal == Approx(std::sqrt(2.0)));
  const SurfaceDistance d = surface_distance(a, a_bvh, b, b_bvh, 0.05, diagonal);
  // Every sample's nearest point is straight above or below it.
  CHECK(d.rms == Approx(0.1 / diagonal).epsilon(1e-12));
  CHECK(d.hausdorff == Approx(0.1 / diagonal).epsilon(1e-12));
  // 4 vertices plus n*n centroids per triangle, n = ceil(sqrt(2) / 0.05) = 29.
  CHECK(d.a_to_b.samples == 4 + 2 * 29 * 29);
  CHECK(d.b_to_a.samples == d.a_to_b.samples);
}

TEST_CASE("two-sided distance sees what one side misses", "[evaluate][analytic]") {
  // a is the left half of b, in the same plane: a -> b is 0 everywhere, b -> a is max(0, x - 1).
  const TriangleMesh a = square(0), b = square(0, 2);
  const TriangleBvh a_bvh(a), b_bvh(b);
  const double spacing = 0.1;
  const SurfaceDistance d = surface_distance(a, a_bvh, b, b_bvh, spacing, 2.0);
  CHECK(d.a_to_b.max < 1e-15);  // rounding in the closest point of a coplanar sample
  CHECK(d.b_to_a.max == Approx(1).epsilon(1e-15));  // the corners at x = 2
  CHECK(d.hausdorff == Approx(0.5).epsilon(1e-15));
  CHECK(d.hausdorff_at.x() == Approx(2).epsilon(1e-15));  // where it is: a sample of b at a corner x = 2
  CHECK((d.hausdorff_at.y() == Approx(0).margin(1e-15) || d.hausdorff_at.y() == Approx(1).epsilon(1e-15)));
  double sum = 0;
  const std::vector<Vec3> b_samples = sample_triangles(b, spacing);
  for (const Vec3& p : b_samples) sum += std::pow(std::max(0.0, p.x() - 1), 2);
  const double all = static_cast<double>(d.a_to_b.samples + b_samples.size());
  CHECK(d.rms == Approx(std::sqrt(sum / all) / 2.0).epsilon(1e-12));
}

TEST_CASE("one-sided distances name the point that is farthest", "[evaluate][analytic]") {
  const TriangleMesh a = square(0);
  const TriangleBvh a_bvh(a);
  const std::vector<Vec3> points{{0.5, 0.5, 0.1}, {0.2, 0.3, -0.4}, {0.9, 0.1, 0.3}, {0.5, 0.5, 0.4}};
  const OneSided d = distances_to(points, a_bvh);
  CHECK(d.max == Approx(0.4).epsilon(1e-12));
  CHECK(d.max_index == 1);  // the first of the two at 0.4
  CHECK(d.samples == points.size());
}

TEST_CASE("samples cover each triangle evenly", "[evaluate][sampling]") {
  TriangleMesh t;
  t.positions = {{0, 0, 0}, {3, 0, 0}, {0.5, 2, 1}, {9, 9, 9}};  // the last vertex is unused
  t.triangles = {0, 1, 2};
  const std::vector<Vec3> s = sample_triangles(t, 0.5);
  const double longest = std::max({(t.positions[1] - t.positions[0]).norm(), (t.positions[2] - t.positions[1]).norm(),
                                   (t.positions[0] - t.positions[2]).norm()});
  const int n = static_cast<int>(std::ceil(longest / 0.5));
  CHECK(n == 7);
  REQUIRE(s.size() == 3 + static_cast<size_t>(n * n));
  Vec3 mean = Vec3::Zero();
  for (size_t k = 3; k < s.size(); ++k) {
    mean += s[k];
    CHECK((closest_point_on_triangle(s[k], t.positions[0], t.positions[1], t.positions[2]) - s[k]).norm() < 1e-12);
  }
  mean /= static_cast<double>(n * n);
  // Equal-area sub-triangles: their centroids average to the triangle's centroid.
  CHECK((mean - (t.positions[0] + t.positions[1] + t.positions[2]) / 3).norm() < 1e-12);
}

TEST_CASE("a limit surface exported and read back is at distance 0 from itself", "[evaluate][export]") {
  auto reference = reference_of("torus.obj", 5);
  REQUIRE(reference.ok());
  CHECK(reference->triangle_count() == 32 * 1024 * 2);
  SurfaceMesh s;
  s.positions = reference->positions;
  s.face_vertices = reference->triangles;
  for (size_t t = 1; t <= reference->triangle_count(); ++t) s.face_offsets.push_back(static_cast<uint32_t>(3 * t));
  const std::string path = (std::filesystem::temp_directory_path() / ("fire_eval_self_" + std::to_string(::getpid()) + ".obj")).string();
  REQUIRE(write_surface(s, path).ok());
  auto back = read_surface(path);
  std::filesystem::remove(path);
  REQUIRE(back.ok());
  auto out = triangulate(back->positions, back->face_offsets, back->face_vertices);
  REQUIRE(out.ok());
  const double diagonal = bounding_box_diagonal(reference->positions);
  const TriangleBvh out_bvh(*out), ref_bvh(*reference);
  const SurfaceDistance d = surface_distance(*out, out_bvh, *reference, ref_bvh, 0.01 * diagonal, diagonal);
  CHECK(d.rms < 1e-14);
  CHECK(d.hausdorff < 1e-14);
  // The control mesh is a coarse polygon around the limit torus: clearly not at distance 0.
  const TriangleMesh control = triangulated_obj("torus.obj");
  const TriangleBvh control_bvh(control);
  const SurfaceDistance far = surface_distance(control, control_bvh, *reference, ref_bvh, 0.01 * diagonal, diagonal);
  CHECK(far.rms > 0.005);
  CHECK(far.hausdorff > far.rms);
}

TEST_CASE("the reference limit surface refuses what cannot be subdivided", "[evaluate][reject]") {
  auto fan = reference_of("fan.obj", 5);
  REQUIRE_FALSE(fan.ok());
  CHECK_THAT(fan.error(), Contains("shared by more than 2 faces"));
  const std::vector<Vec3> nan_points = {{0, 0, 0}, {1, 0, 0}, {1, std::nan(""), 0}, {0, 1, 0}};
  const std::vector<uint32_t> offsets = {0, 4}, quad = {0, 1, 2, 3};
  auto nan = reference_limit_surface(nan_points, offsets, quad, 5);
  REQUIRE_FALSE(nan.ok());
  CHECK_THAT(nan.error(), Contains("non-finite"));
  // A dense surface as the reference: refused by its size at `levels`, before anything is subdivided.
  std::vector<uint32_t> dense_offsets = {0}, dense_quads;
  for (uint32_t f = 0; f < 16385; ++f) {
    dense_quads.insert(dense_quads.end(), {0, 1, 2, 3});
    dense_offsets.push_back(static_cast<uint32_t>(dense_quads.size()));
  }
  auto dense = reference_limit_surface(nan_points, dense_offsets, dense_quads, 5);
  REQUIRE_FALSE(dense.ok());
  CHECK_THAT(dense.error(), Contains("16385 faces make 16778240 quads at 5 Catmull-Clark levels, more than the 16777216"));
  // At 4 levels (4.2 million quads) the size passes, and the NaN point is what is refused.
  auto fewer_levels = reference_limit_surface(nan_points, dense_offsets, dense_quads, 4);
  REQUIRE_FALSE(fewer_levels.ok());
  CHECK_THAT(fewer_levels.error(), Contains("non-finite"));
  auto bad = triangulate(nan_points, offsets, std::vector<uint32_t>{0, 1, 9, 3});
  REQUIRE_FALSE(bad.ok());
  CHECK_THAT(bad.error(), Contains("vertex 2 has a non-finite coordinate"));
  const std::vector<Vec3> ok_points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  auto out_of_range = triangulate(ok_points, offsets, std::vector<uint32_t>{0, 1, 9, 3});
  REQUIRE_FALSE(out_of_range.ok());
  CHECK_THAT(out_of_range.error(), Contains("face 0 refers to vertex 9 of 4"));
}

TEST_CASE("topology: Euler characteristic and border loops of every shared mesh, welded seams count once", "[evaluate][topology]") {
  struct Expected {
    const char* mesh;
    int64_t euler;
    size_t border_loops, nonmanifold_edges;
  };
  // 2 - 2 genus - border loops, from the meshes' README.
  const Expected expected[] = {{"pawn", 1, 1, 0},  {"rook", 1, 1, 0}, {"torus", 0, 0, 0}, {"cube", 2, 0, 0},
                               {"lampshade", 0, 2, 0}, {"mug", -1, 1, 0}, {"egg", 2, 0, 0}, {"fan", 1, 1, 4}};
  for (const Expected& e : expected) {
    INFO(e.mesh);
    auto mesh = read_obj(kMeshes + e.mesh + ".obj");
    REQUIRE(mesh);
    const Topology t = topology(mesh->positions, mesh->face_offsets, mesh->face_vertices);
    CHECK(t.nonmanifold_edges == e.nonmanifold_edges);
    if (e.nonmanifold_edges > 0) continue;
    CHECK(t.euler_characteristic == e.euler);
    CHECK(t.border_loops == e.border_loops);
  }
  // The cube written face by face, each face with its own four corners (as a patch-by-patch export writes
  // seams twice): welded, the same closed surface.
  auto cube = read_obj(kMeshes + "cube.obj");
  REQUIRE(cube);
  std::vector<Vec3> positions;
  std::vector<uint32_t> offsets{0}, vertices;
  for (size_t f = 0; f + 1 < cube->face_offsets.size(); ++f) {
    for (uint32_t k = cube->face_offsets[f]; k < cube->face_offsets[f + 1]; ++k) {
      vertices.push_back(uint32_t(positions.size()));
      positions.push_back(cube->positions[cube->face_vertices[k]]);
    }
    offsets.push_back(uint32_t(vertices.size()));
  }
  const Topology apart = topology(positions, offsets, vertices);
  CHECK(apart.vertices == 8);
  CHECK(apart.euler_characteristic == 2);
  CHECK(apart.border_loops == 0);
  // One face left out opens one border loop.
  offsets.pop_back();
  const Topology open = topology(positions, offsets, vertices);
  CHECK(open.euler_characteristic == 1);
  CHECK(open.border_loops == 1);
  CHECK(open.border_edges == 4);
}

namespace {

// A strip along x, folded along the x axis: one side runs along +y in the plane z = 0, the other leaves the axis at
// `fold_deg` from the first side's plane (0: flat on, 90: up, a box's edge); `rounded` > 0 replaces the fold by an
// arc of that radius. Quads of 1 mm.
TriangleMesh folded_strip(double fold_deg, double rounded = 0) {
  std::vector<Vec3> profile;  // the cross-section in (y, z), from the far end of the flat side to the far end of the other
  const double fold = fold_deg * std::numbers::pi / 180;
  const Vec3 out(0, -std::cos(fold), std::sin(fold));  // the second side's direction, away from the axis
  for (int i = 40; i >= 1; --i) profile.push_back(Vec3(0, 0.001 * i, 0));
  if (rounded > 0) {
    for (int k = 0; k <= 16; ++k) {  // an arc tangent to both sides, turning by `fold`
      const double a = fold * k / 16;
      profile.push_back(Vec3(0, -rounded * std::sin(a), rounded * (1 - std::cos(a))));
    }
  } else {
    profile.push_back(Vec3::Zero());
  }
  const Vec3 start = profile.back();
  for (int i = 1; i <= 40; ++i) profile.push_back(start + 0.001 * i * out);
  TriangleMesh mesh;
  const int columns = 61;  // x from -0.03 to 0.03
  for (int c = 0; c < columns; ++c)
    for (const Vec3& q : profile) mesh.positions.push_back(Vec3(0.001 * (c - 30), q.y(), q.z()));
  const auto rows = static_cast<uint32_t>(profile.size());
  for (uint32_t c = 0; c + 1 < columns; ++c)
    for (uint32_t r = 0; r + 1 < rows; ++r) {
      const uint32_t a = c * rows + r, b = a + rows;
      mesh.triangles.insert(mesh.triangles.end(), {a, b, b + 1, a, b + 1, a + 1});
    }
  return mesh;
}

}  // namespace

TEST_CASE("the bend across a curve: 0 on a plane, the fold's angle across a fold, less where it is rounded", "[evaluate][crease]") {
  const Vec3 along = Vec3::UnitX();
  for (double fold : {0.0, 30.0, 90.0, 120.0}) {
    const TriangleMesh mesh = folded_strip(fold);
    const TriangleBvh bvh(mesh);
    const std::optional<double> bend = bend_across_deg(bvh, Vec3::Zero(), along, 0.005);
    REQUIRE(bend);
    CHECK(*bend == Approx(fold).margin(1.0));
    // A point 1 mm off the fold, on the flat side (a tracked curve beside the crease), reads the same bend.
    const std::optional<double> beside = bend_across_deg(bvh, Vec3(0, 0.001, 0), along, 0.005);
    REQUIRE(beside);
    CHECK(*beside == Approx(fold).margin(2.0));
  }
  // Rounded over 10 mm, a box's edge bends less within 5 mm of it: what a smooth surface does where a crease was meant.
  const TriangleBvh rounded(folded_strip(90, 0.01));
  const std::optional<double> smooth = bend_across_deg(rounded, Vec3::Zero(), along, 0.005);
  REQUIRE(smooth);
  CHECK(*smooth < 80);
  // At the strip's border there is one side only.
  const TriangleBvh flat(folded_strip(0));
  CHECK_FALSE(bend_across_deg(flat, Vec3(0, 0.04, 0), along, 0.005));
  CHECK_FALSE(bend_across_deg(flat, Vec3::Zero(), Vec3::Zero(), 0.005));
}
