// Bounding volume hierarchy for closest-point queries and ray casts on triangles.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

#include "systems/evaluate/evaluate.hpp"

namespace fire::evaluate {

namespace {

constexpr uint32_t kLeafSize = 4;

double box_distance_squared(const Vec3& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).squaredNorm();
}

// Entry parameter of the ray into the box (0 if it starts inside), or infinity if it misses it.
double box_entry(const Vec3& origin, const Vec3& inverse, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  double t_in = 0, t_out = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    double a = (lo[k] - origin[k]) * inverse[k], b = (hi[k] - origin[k]) * inverse[k];
    if (std::isnan(a) || std::isnan(b)) {  // parallel to the slab and on its plane: inside along this axis
      if (origin[k] < lo[k] || origin[k] > hi[k]) return std::numeric_limits<double>::infinity();
      continue;
    }
    if (a > b) std::swap(a, b);
    t_in = std::max(t_in, a);
    t_out = std::min(t_out, b);
  }
  return t_in <= t_out ? t_in : std::numeric_limits<double>::infinity();
}

// Möller-Trumbore: the ray parameter where it meets triangle abc, or infinity.
double triangle_hit(const Vec3& origin, const Vec3& direction, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = b - a, e2 = c - a, h = direction.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-300) return std::numeric_limits<double>::infinity();  // parallel or degenerate
  const double inv = 1.0 / det;
  const Vec3 s = origin - a;
  const double u = inv * s.dot(h);
  if (u < 0.0 || u > 1.0) return std::numeric_limits<double>::infinity();
  const Vec3 q = s.cross(e1);
  const double v = inv * direction.dot(q);
  if (v < 0.0 || u + v > 1.0) return std::numeric_limits<double>::infinity();
  const double t = inv * e2.dot(q);
  return t > 0.0 ? t : std::numeric_limits<double>::infinity();
}

}  // namespace

TriangleBvh::TriangleBvh(const TriangleMesh& mesh) {
  const auto count = static_cast<uint32_t>(mesh.triangle_count());
  if (count == 0) return;
  std::vector<Vec3> centroids(count);
  for (uint32_t t = 0; t < count; ++t)
    centroids[t] = (mesh.positions[mesh.triangles[3 * t]] + mesh.positions[mesh.triangles[3 * t + 1]] +
                    mesh.positions[mesh.triangles[3 * t + 2]]) / 3;
  order_.resize(count);
  std::iota(order_.begin(), order_.end(), 0u);
  nodes_.reserve(2 * (count / kLeafSize + 1));
  nodes_.push_back({});
  build(0, 0, count, mesh, centroids);
  slot_of_.resize(count);
  corners_.resize(3 * size_t{count});
  for (uint32_t slot = 0; slot < count; ++slot) {
    slot_of_[order_[slot]] = slot;
    for (int k = 0; k < 3; ++k) corners_[3 * size_t{slot} + k] = mesh.positions[mesh.triangles[3 * order_[slot] + k]];
  }
}

void TriangleBvh::build(uint32_t node, uint32_t begin, uint32_t end, const TriangleMesh& mesh,
                        const std::vector<Vec3>& centroids) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  Eigen::Vector3d centroid_lo = lo, centroid_hi = hi;
  for (uint32_t slot = begin; slot < end; ++slot) {
    const uint32_t t = order_[slot];
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = mesh.positions[mesh.triangles[3 * t + k]];
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    centroid_lo = centroid_lo.cwiseMin(centroids[t]);
    centroid_hi = centroid_hi.cwiseMax(centroids[t]);
  }
  nodes_[node].lo = lo;
  nodes_[node].hi = hi;
  if (end - begin <= kLeafSize) {
    nodes_[node].first = begin;
    nodes_[node].count = end - begin;
    return;
  }
  int axis = 0;
  (centroid_hi - centroid_lo).maxCoeff(&axis);
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                   [&](uint32_t x, uint32_t y) { return centroids[x][axis] < centroids[y][axis]; });
  // Children are allocated together so that the right one is always left + 1.
  const auto left = static_cast<uint32_t>(nodes_.size());
  nodes_.push_back({});
  nodes_.push_back({});
  nodes_[node].first = left;
  nodes_[node].count = 0;
  build(left, begin, mid, mesh, centroids);
  build(left + 1, mid, end, mesh, centroids);
}

TriangleBvh::Hit TriangleBvh::closest(const Vec3& p, uint32_t hint) const {
  Hit best;
  best.distance_squared = std::numeric_limits<double>::infinity();
  if (nodes_.empty()) return best;
  auto try_slot = [&](uint32_t slot) {
    const Vec3* c = &corners_[3 * size_t{slot}];
    const Vec3 q = closest_point_on_triangle(p, c[0], c[1], c[2]);
    const double d = (q - p).squaredNorm();
    if (d < best.distance_squared) {
      best.distance_squared = d;
      best.point = q;
      best.triangle = order_[slot];
    }
  };
  if (hint < slot_of_.size()) try_slot(slot_of_[hint]);
  // A balanced tree over at most 2^32 triangles is at most 32 deep; each level leaves one node pending.
  std::array<uint32_t, 64> stack;
  size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (box_distance_squared(p, node.lo, node.hi) >= best.distance_squared) continue;
    if (node.count > 0) {
      for (uint32_t slot = node.first; slot < node.first + node.count; ++slot) try_slot(slot);
      continue;
    }
    const double d_left = box_distance_squared(p, nodes_[node.first].lo, nodes_[node.first].hi);
    const double d_right = box_distance_squared(p, nodes_[node.first + 1].lo, nodes_[node.first + 1].hi);
    // Visit the nearer child first: push it last.
    const bool left_first = d_left <= d_right;
    const uint32_t near = left_first ? node.first : node.first + 1, far = left_first ? node.first + 1 : node.first;
    const double d_near = left_first ? d_left : d_right, d_far = left_first ? d_right : d_left;
    if (d_far < best.distance_squared) stack[top++] = far;
    if (d_near < best.distance_squared) stack[top++] = near;
  }
  return best;
}

TriangleBvh::Hit TriangleBvh::ray_cast(const Vec3& origin, const Vec3& direction) const {
  Hit best;
  double best_t = std::numeric_limits<double>::infinity();
  if (nodes_.empty()) return best;
  const Vec3 inverse = direction.cwiseInverse();  // +-infinity on an axis the ray does not move along
  std::array<uint32_t, 64> stack;
  size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    const double entry = box_entry(origin, inverse, node.lo, node.hi);
    if (entry == std::numeric_limits<double>::infinity() || entry > best_t) continue;
    if (node.count > 0) {
      for (uint32_t slot = node.first; slot < node.first + node.count; ++slot) {
        const Vec3* c = &corners_[3 * size_t{slot}];
        const double t = triangle_hit(origin, direction, c[0], c[1], c[2]);
        if (t < best_t || (t == best_t && t < std::numeric_limits<double>::infinity() && order_[slot] < best.triangle)) {
          best_t = t;
          best.triangle = order_[slot];
        }
      }
      continue;
    }
    // Nearer box first: push it last.
    const double t_left = box_entry(origin, inverse, nodes_[node.first].lo, nodes_[node.first].hi);
    const double t_right = box_entry(origin, inverse, nodes_[node.first + 1].lo, nodes_[node.first + 1].hi);
    const bool left_first = t_left <= t_right;
    const uint32_t near = left_first ? node.first : node.first + 1, far = left_first ? node.first + 1 : node.first;
    // The parents' checks would drop a missed box too; this keeps the stack to boxes the ray may meet.
    const double t_near = std::min(t_left, t_right), t_far = std::max(t_left, t_right);
    const double inf = std::numeric_limits<double>::infinity();
    if (t_far < inf && t_far <= best_t) stack[top++] = far;
    if (t_near < inf && t_near <= best_t) stack[top++] = near;
  }
  if (best.triangle != kNoTriangle) {
    best.point = origin + best_t * direction;
    best.distance_squared = best_t * best_t * direction.squaredNorm();
  }
  return best;
}

}  // namespace fire::evaluate
