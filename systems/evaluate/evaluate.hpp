#pragma once
// Distances between surfaces, for measuring a reconstruction against its ground truth.
//
// The measure (`fire eval`): both surfaces are triangulated and densely sampled (every vertex, plus the
// centroids of the n*n sub-triangles of a regular n-split of each triangle, n = ceil(longest edge /
// spacing)); each sample's distance is the exact distance to the closest point of the other surface's
// triangles, found with a bounding volume hierarchy. Distances are divided by a scale (the bounding-box
// diagonal of the reference limit surface). rms is the square root of the mean of the squared distances
// over the samples of both directions together; hausdorff is the largest distance in either direction.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "engine/common.hpp"

namespace fire::evaluate {

inline constexpr uint32_t kNoTriangle = 0xffffffffu;

struct TriangleMesh {
  std::vector<Vec3> positions;
  std::vector<uint32_t> triangles;  // 3 vertex indices per triangle
  size_t triangle_count() const { return triangles.size() / 3; }
};

// Fan triangulation (v0, vi, vi+1) of polygons given as flat offsets + vertex indices.
// Errors: no faces, a face with fewer than 3 vertices, an index out of range, a non-finite position.
Result<TriangleMesh> triangulate(std::span<const Vec3> positions, std::span<const uint32_t> face_offsets,
                                 std::span<const uint32_t> face_vertices);

// A polygon mesh's topology after welding coincident vertices (equal coordinates): V, E and F, the Euler
// characteristic V - E + F, the edges one face uses (border) or more than two (non-manifold), and the border
// loops, counted as connected pieces of the border edges.
struct Topology {
  size_t vertices = 0, edges = 0, faces = 0;
  int64_t euler_characteristic = 0;
  size_t border_edges = 0, border_loops = 0, nonmanifold_edges = 0;
};
Topology topology(std::span<const Vec3> positions, std::span<const uint32_t> face_offsets,
                  std::span<const uint32_t> face_vertices);

// The exact closest point of triangle abc to p (all seven Voronoi regions: three vertices, three edges,
// the face). A degenerate triangle is treated as its three edges.
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);
// The closest point of segment ab to p (a point when a == b).
Vec3 closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b);

// A binary bounding volume hierarchy over a mesh's triangles (median split on the longest axis,
// up to 4 triangles per leaf) answering exact closest-point queries and ray casts (the app's mouse pen).
class TriangleBvh {
 public:
  explicit TriangleBvh(const TriangleMesh& mesh);

  struct Hit {
    Vec3 point = Vec3::Zero();
    double distance_squared = 0;
    uint32_t triangle = kNoTriangle;  // index in the mesh's triangle list
  };
  // `hint`: a triangle likely to be close (e.g. the previous query's), which tightens the search bound
  // from the start. The result does not depend on the hint except among equally close triangles.
  Hit closest(const Vec3& p, uint32_t hint = kNoTriangle) const;
  // The first triangle a ray meets (from either side), at ray parameter t > 0: point = origin + t * direction,
  // distance_squared its squared distance to origin; triangle == kNoTriangle when it meets none. Equal t on
  // several triangles (a shared edge): the lowest triangle index.
  Hit ray_cast(const Vec3& origin, const Vec3& direction) const;
  size_t node_count() const { return nodes_.size(); }

 private:
  struct Node {
    Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
    uint32_t first = 0;  // leaf: first slot in order_; inner: index of the left child (the right is first + 1)
    uint32_t count = 0;  // leaf: triangle count; 0 for an inner node
  };
  void build(uint32_t node, uint32_t begin, uint32_t end, const TriangleMesh& mesh, const std::vector<Vec3>& centroids);
  std::vector<Node> nodes_;
  std::vector<uint32_t> order_;    // triangle indices, grouped by leaf
  std::vector<uint32_t> slot_of_;  // inverse of order_
  std::vector<Vec3> corners_;      // 3 per slot of order_, for locality
};

// Sample points of a triangle mesh: its referenced vertices, then per triangle the n*n sub-triangle
// centroids (n = max(1, ceil(longest edge / spacing))). spacing > 0.
std::vector<Vec3> sample_triangles(const TriangleMesh& mesh, double spacing);

// Distances of points to a surface, in the units of the points.
struct OneSided {
  double sum_squared = 0;
  double max = 0;
  size_t max_index = 0;  // the point at distance max: where a figure is worst, to look there
  size_t samples = 0;
  double rms() const;
};
OneSided distances_to(std::span<const Vec3> points, const TriangleBvh& target);

// Two-sided distance between surfaces a and b, every figure divided by `scale`.
struct SurfaceDistance {
  double rms = 0;        // sqrt of the mean squared distance over the samples of both directions
  double hausdorff = 0;  // largest distance, both directions
  OneSided a_to_b, b_to_a;  // unscaled
  Vec3 hausdorff_at{};      // the sample, on a or on b, at the largest distance
};
SurfaceDistance surface_distance(const TriangleMesh& a, const TriangleBvh& a_bvh, const TriangleMesh& b,
                                 const TriangleBvh& b_bvh, double spacing, double scale);

// The ground truth of a control mesh: Catmull-Clark (fire_subdivide: EdgeAndCorner, or with `border_corners`
// the border's corners given; `sharp_edges` infinitely sharp) to `levels` and the last level's vertices
// projected to their limit positions, each quad split along its shorter diagonal.
// Errors are fire_subdivide's (non-manifold edge or vertex, bad faces, non-finite positions, size), and
// more than kMaxReferenceQuads quads at `levels`.
inline constexpr uint64_t kMaxReferenceQuads = uint64_t{1} << 24;
Result<TriangleMesh> reference_limit_surface(std::span<const Vec3> positions, std::span<const uint32_t> face_offsets,
                                             std::span<const uint32_t> face_vertices, int levels,
                                             std::span<const uint32_t> sharp_edges = {},
                                             std::span<const uint8_t> border_corners = {});

// How far a surface bends across a curve on it, at point p with the curve's tangent t: the surface is cut by the
// plane through p normal to t, and each of the cut's two branches is read as its chord from `radius` to twice
// that from p (closest points of rings of probes), which p a little off the crease does not tilt. The result is
// 180 degrees less the angle between the branches: 0 where the surface goes on flat across the curve, 90 across
// a box's edge. nullopt where the cut does not show two branches there (p off the surface, or at its border).
std::optional<double> bend_across_deg(const TriangleBvh& surface, const Vec3& p, const Vec3& t, double radius);

}  // namespace fire::evaluate
