#pragma once
// The snapping index (thesis 5.5): a bounding-volume hierarchy over the polyline points of the mesh's live
// edges, kept in step with the mesh by incremental updates instead of rebuilds.
//
// Leaves are runs of up to kLeafPoints consecutive points of one polyline (a curve is spatially coherent
// along its length, so a run's box is thin); inner nodes form a dynamic AABB tree that stays balanced
// under insertion and removal of leaves. The index holds its own copy of the points, so it answers
// between syncs without reading the mesh, and compaction only relabels edges.
//
// Answers and tie-breaks equal the exhaustive searches of the sketch system: distances are computed with
// the same expression, `(q - p).norm()`, and pruning is conservative, so a tie is never cut off.
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "engine/change.hpp"
#include "engine/mesh.hpp"

namespace fire {

// A polyline point: edge slot, index in the edge's polyline, distance to the query.
struct SnapHit {
  uint32_t edge = kNone;
  uint32_t point = kNone;
  double distance = std::numeric_limits<double>::infinity();
  bool found() const { return edge != kNone; }
  friend bool operator==(const SnapHit&, const SnapHit&) = default;
};

// The edge slots to hand to SnapIndex::update: those whose stamp (ChangeStamps::stamp) is later than `seen`.
std::vector<uint32_t> changed_slots(std::span<const Frame> stamps, Frame seen);
// The same from per-slot dirty tags (the pools' `dirty`): the tagged slots.
std::vector<uint32_t> changed_slots(std::span<const uint8_t> dirty);

class SnapIndex {
 public:
  static constexpr uint32_t kLeafPoints = 8;
  static constexpr double kUnbounded = std::numeric_limits<double>::infinity();

  // Brings the index in step with `mesh` for these edge slots, each of which may now be dead, alive with a
  // new polyline, or new; slots the mesh no longer has (truncated by undo) are dropped as well. A slot
  // whose polyline is unchanged costs a comparison.
  void update(const Mesh& mesh, std::span<const uint32_t> changed_edge_slots);
  // Relabels the edges after Mesh::compact (no geometry is touched).
  void remap(const CompactionMap& map);
  void clear();

  // Nearest polyline point within `radius` (distance <= radius); ties go to the lowest edge slot, then the
  // lowest point index. Vertices are the ends of their edges' polylines.
  SnapHit nearest(const Vec3& p, double radius = kUnbounded) const;
  // Nearest point of face f's boundary within `radius`; ties go to the edge first in f's loop, then the
  // lowest point index (the order sketch's exhaustive search walks the boundary in).
  SnapHit nearest_on_face(const Mesh& mesh, uint32_t f, const Vec3& p, double radius = kUnbounded) const;
  // For every edge with a point within `radius`: its nearest point (lowest index on ties), by edge slot.
  void nearest_per_edge(const Vec3& p, double radius, std::vector<SnapHit>& out) const;

  size_t point_count() const { return points_; }
  size_t edge_count() const { return edges_; }
  // Empty when the index holds exactly the live edges of `mesh` with their polylines and the tree is sound.
  std::string validate(const Mesh& mesh) const;

 private:
  struct Box {
    double lo[3], hi[3];
  };
  struct Node {
    Box box;
    uint32_t child[2];  // child[0] == kNone for a tree leaf, whose child[1] is the leaf record
    uint32_t parent;
    int32_t height;     // 0 for a tree leaf
  };
  struct Leaf {
    uint32_t edge, first, count, node;
    double x[kLeafPoints], y[kLeafPoints], z[kLeafPoints];
  };

  bool same_polyline(uint32_t e, std::span<const Vec3> line) const;
  void remove_edge(uint32_t e);
  void add_leaves(uint32_t e, std::span<const Vec3> line, std::vector<uint32_t>& fresh);
  uint32_t new_node();
  void free_node(uint32_t n);
  void insert_leaf(uint32_t node);
  void remove_leaf(uint32_t node);
  uint32_t balance(uint32_t a);
  void refit_up(uint32_t n);
  void rebuild();
  uint32_t build(std::span<uint32_t> leaves, uint32_t parent);
  std::string validate_node(uint32_t n, uint32_t parent, size_t& leaves) const;

  std::vector<Node> nodes_;
  std::vector<uint32_t> free_nodes_;
  std::vector<Leaf> leaves_;
  std::vector<uint32_t> free_leaves_;
  std::vector<std::vector<uint32_t>> edge_leaves_;  // per edge slot: its leaf records in point order
  uint32_t root_ = kNone;
  size_t points_ = 0, edges_ = 0;
};

}  // namespace fire
