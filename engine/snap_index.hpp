#pragma once
// The snapping index (thesis 5.5): a bounding-volume hierarchy over the polyline points of the mesh's live
// edges, kept in step with the mesh by incremental updates instead of rebuilds.
//
// Leaves are runs of up to kLeafPoints consecutive points of one polyline (a curve is spatially coherent
// along its length, so a run's box is thin); inner nodes form a dynamic binary AABB tree: a new leaf goes
// next to the sibling that adds the least box area, and a subtree that grows too deep for its size is
// rebuilt top-down by the surface area heuristic (as a scapegoat tree does), which keeps the depth
// logarithmic without rotations that would pair far-apart subtrees. Each inner node also carries its
// great-grandchildren's boxes, so queries read every third level. A removed run stays in the tree as a
// dead record (NaN points) until dead records are an eighth of the live ones. The index holds its own copy
// of the points, so it answers between syncs without reading the mesh, and compaction only relabels edges.
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
  EdgeIndex edge;
  uint32_t point = kNone;
  double distance = std::numeric_limits<double>::infinity();
  bool found() const { return edge != kNone; }
  friend bool operator==(const SnapHit&, const SnapHit&) = default;
};

// The edge slots to hand to SnapIndex::update: those whose stamp (ChangeStamps::stamp) is later than `seen`.
std::vector<uint32_t> changed_slots(std::span<const Frame> stamps, Frame seen);

class SnapIndex {
 public:
  static constexpr uint32_t kLeafPoints = 8;  // even: queries read points in pairs
  static constexpr double kUnbounded = std::numeric_limits<double>::infinity();

  // Brings the index in step with `mesh` for these edge slots, each of which may now be dead, alive with a
  // new polyline, or new; slots the mesh no longer has (truncated by undo) are dropped as well. A slot
  // whose polyline is unchanged costs a comparison.
  void update(const Mesh& mesh, std::span<const uint32_t> changed_edge_slots);
  // Relabels the edges after Mesh::compact (no geometry is touched), so update() must have seen the frame
  // before compaction.
  void remap(const CompactionMap& map);
  void clear();
  // The end-of-frame sync: brings the index in step with every edge `mesh` stamped after the frame of the
  // last sync, relabelling first when the mesh was compacted once since then; the first time, or after
  // more than one compaction, it indexes every live edge afresh. Call it after the frame's last write.
  void sync(const Mesh& mesh);

  // Nearest polyline point within `radius` (distance <= radius); ties go to the lowest edge slot, then the
  // lowest point index. Vertices are the ends of their edges' polylines.
  SnapHit nearest(const Vec3& p, double radius = kUnbounded) const;
  // Nearest point of face f's boundary within `radius`; ties go to the edge first in f's loop, then the
  // lowest point index (the order sketch's exhaustive search walks the boundary in).
  SnapHit nearest_on_face(const Mesh& mesh, FaceIndex f, const Vec3& p, double radius = kUnbounded) const;
  // For every edge with a point within `radius`: its nearest point (lowest index on ties), by edge slot.
  void nearest_per_edge(const Vec3& p, double radius, std::vector<SnapHit>& out) const;

  size_t point_count() const { return points_; }
  size_t edge_count() const { return edges_; }
  // Nodes on the longest path from the root to a leaf record, counting both (0 when empty).
  uint32_t height() const;
  // Empty when the index holds exactly the live edges of `mesh` with their polylines and the tree is sound.
  std::string validate(const Mesh& mesh) const;

 private:
  // Single precision rounded outwards: fewer bytes per node, and a box still holds its points.
  struct Box {
    float lo[3], hi[3];
  };
  // An inner node is a binary node (child[]) that holds its great-grandchildren's boxes and references
  // (entries), so a query decides on eight subtrees from the one node it has loaded and skips two levels of
  // dependent loads. Entries 4s to 4s+3 lie under child s, in the order of the paths to them; a leaf
  // record met on the way down takes the first entry of its range and leaves the rest empty (kNone, NaN
  // box). mid[] holds the grandchildren in the same way, so that a parent can fill its own entries from
  // this node alone; child s's box is the union of its entries. Boxes axis by axis ([axis][entry]), so a
  // query computes the distances two entries at a time. A reference is an inner node or a leaf record
  // (kLeafRef set).
  struct alignas(64) Node {  // four cache lines
    float lo[3][8], hi[3][8];
    uint32_t entry[8];
    uint32_t mid[4];
    uint32_t child[2];
    Box entry_box(int k) const {
      return {{lo[0][k], lo[1][k], lo[2][k]}, {hi[0][k], hi[1][k], hi[2][k]}};
    }
    Box box(int s) const;  // of child s: the union of entries 4s to 4s+3
    void set_entry(int k, uint32_t ref, const Box& b) {
      entry[k] = ref;
      for (int a = 0; a < 3; ++a) {
        lo[a][k] = b.lo[a];
        hi[a][k] = b.hi[a];
      }
    }
  };
  static constexpr uint32_t kLeafRef = 0x80000000u;
  static constexpr uint32_t kFreed = kNone - 1;  // Info::parent of a node on the free list
  struct alignas(64) Leaf {  // four cache lines
    Box box;
    uint32_t edge, first, count, parent;  // parent: inner node, or kNone at the root
    double x[kLeafPoints], y[kLeafPoints], z[kLeafPoints];
  };
  struct Item {  // a child reference with its box, while building
    uint32_t ref;
    Box box;
  };

  bool same_polyline(uint32_t e, std::span<const Vec3> line) const;
  void remove_edge(uint32_t e);
  void purge_dead();
  void add_leaves(uint32_t e, std::span<const Vec3> line, std::vector<uint32_t>& fresh);
  uint32_t new_node();
  uint32_t& parent_of(uint32_t ref) { return ref & kLeafRef ? leaves_[ref & ~kLeafRef].parent : info_[ref].parent; }
  int32_t height_of(uint32_t ref) const { return ref & kLeafRef ? 0 : info_[ref].height; }
  uint32_t leaves_of(uint32_t ref) const { return ref & kLeafRef ? 1 : info_[ref].leaves; }
  Box box_of(uint32_t ref) const;
  void fill_entries(Node& n, int s) const;
  void fill(uint32_t node, int s) { fill_entries(nodes_[node], s); }
  void replace_child(uint32_t parent, uint32_t old_ref, uint32_t new_ref);
  void insert_leaf(uint32_t ref);
  void remove_leaf(uint32_t ref);
  void refit_up(uint32_t node);
  void refit_path(uint32_t node);
  void refit_touched();
  void refit_marked(uint32_t node, std::vector<uint32_t>& unbalanced);
  void rebuild();
  void rebuild_subtree(uint32_t node);
  void build(std::span<Item> items, uint32_t node, uint32_t parent);
  void prefetch(uint32_t ref) const;
  std::string validate_ref(uint32_t ref, uint32_t parent, const Box& box, size_t& leaves, size_t& dead) const;

  std::vector<Node> nodes_;
  // Per inner node, what only updates read, together so that a refit misses once per node.
  struct Info {
    uint32_t parent = kNone;
    int32_t height = 0;  // edges to the deepest leaf record below
    uint32_t leaves = 0;
    uint8_t marked = 0;  // scratch of refit_touched(), all clear between calls
  };
  std::vector<Info> info_;
  std::vector<uint32_t> touched_;  // nodes whose subtree changed since the last refit
  // Scratch of refit_touched(), kept to spare allocations.
  std::vector<uint32_t> marked_list_, unbalanced_;
  std::vector<uint32_t> free_nodes_;
  std::vector<Leaf> leaves_;
  std::vector<uint32_t> free_leaves_;
  std::vector<uint32_t> dead_leaves_;  // in the tree, but of removed runs (remove_edge)
  std::vector<std::vector<uint32_t>> edge_leaves_;  // per edge slot: its leaf records in point order
  uint32_t root_ = kNone;                           // a child reference
  Box root_box_ = {};                               // box_of(root_), kept by update() and remap()
  size_t points_ = 0, edges_ = 0;
  // What sync() has seen of the mesh.
  bool synced_ = false;
  Frame synced_frame_ = 0;
  uint64_t synced_compactions_ = 0;
};

}  // namespace fire
