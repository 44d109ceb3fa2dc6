// Bounding volume hierarchy for closest-point queries on triangles.
#include <algorithm>
#include <array>
#include <limits>
#include <numeric>

#include "systems/evaluate/evaluate.hpp"

namespace fire::evaluate {

namespace {

constexpr uint32_t kLeafSize = 4;

double box_distance_squared(const Vec3& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).squaredNorm();
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

}  // namespace fire::evaluate
