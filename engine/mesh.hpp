#pragma once
// The polyline mesh M = (V, E, F, P) of thesis chapter 5, held in structure-of-arrays pools.
//
// - Points: every polyline sample of every edge, in one contiguous column. An edge owns the range
//   [point_offset, point_offset + point_count); its first and last points equal its two vertices.
// - Faces refer to their edges through one flat column of oriented edges (edge << 1 | reversed),
//   with a per-face offset and count, in loop order.
// - E -> 2V; E -> <=2F with face[0] the face that walks the edge from vertex[0] to vertex[1] and face[1]
//   the one that walks it backwards; V -> E as an intrusive list (first_edge, then next[] per edge end).
// - Dead elements are tombstones (flag kAlive cleared, generation bumped) on a free list; compact()
//   squeezes them out and returns old-to-new maps.
// Every column is journaled: mutations made inside a transaction can be rolled back bit for bit.
// Every write stamps the element with the current frame (engine/change.hpp), rollback included, so any
// number of consumers can ask what changed since the frame they last saw.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "engine/change.hpp"
#include "engine/column.hpp"
#include "engine/common.hpp"
#include "engine/mesh_index.hpp"

namespace fire {

// A typed reference that outlives a frame: the slot index plus the generation the slot had.
template <class Tag>
struct Handle {
  uint32_t index = kNone;
  uint32_t generation = 0;
  bool valid() const { return index != kNone; }
  friend bool operator==(const Handle&, const Handle&) = default;
};
using VertexId = Handle<VertexTag>;
using EdgeId = Handle<EdgeTag>;
using FaceId = Handle<FaceTag>;

// An edge as it appears in a face loop.
inline OrientedEdge make_oriented(EdgeIndex edge, bool reversed) { return OrientedEdge{edge << 1 | (reversed ? 1u : 0u)}; }
inline EdgeIndex edge_of(OrientedEdge oriented) { return EdgeIndex{oriented >> 1}; }
inline bool is_reversed(OrientedEdge oriented) { return oriented & 1u; }

enum ElementFlag : uint8_t {
  kAlive = 1,
  kSplitVertex = 2,  // vertex made by splitting an edge: joined again when no curve needs it
  kSharpEdge = 4,    // crease for subdivision
  kBridgeEdge = 8,   // a curve between two border loops across their hole, no face yet: the second one makes the faces
  kPendingEdge = 16, // a piece of a stroke that ended off the network: no face, apart from the network, drawn on from its free end
};

struct VertexPool {
  Column<Vec3> position;
  Column<uint32_t> first_edge;
  Column<uint32_t> generation;
  Column<uint8_t> flags;
  Column<uint32_t> free_list;
  ChangeStamps changes;  // not journaled: rollback stamps what it restores
};

struct EdgePool {
  Column<std::array<uint32_t, 2>> vertex;
  Column<std::array<uint32_t, 2>> face;
  Column<std::array<uint32_t, 2>> next;  // next[s]: next edge in the list of vertex[s]
  Column<uint32_t> point_offset;
  Column<uint32_t> point_count;
  Column<uint32_t> generation;
  Column<uint8_t> flags;
  Column<uint32_t> free_list;
  ChangeStamps changes;
};

struct FacePool {
  Column<uint32_t> edge_offset;
  Column<uint32_t> edge_count;
  Column<uint32_t> generation;
  Column<uint8_t> flags;
  Column<uint32_t> free_list;
  ChangeStamps changes;
};

// A closed polyline's centroid and unit mean normal (Newell's; zero for a loop that encloses no area).
struct LoopPlane {
  Vec3 centroid = Vec3::Zero(), normal = Vec3::Zero();
};
LoopPlane loop_plane(std::span<const Vec3> loop);

struct MeshMark;
class SnapshotWriter;
class SnapshotReader;

// Old-to-new slot maps produced by compaction (kNone for removed slots).
struct CompactionMap {
  std::vector<uint32_t> vertex, edge, face;
};

// The last compaction, kept for consumers: one that saw compaction `count - 1` remaps its caches through
// `map`; one that is further behind starts over.
struct CompactionRecord {
  uint64_t count = 0;
  Frame frame = 0;
  CompactionMap map;
};

class Mesh {
 public:
  VertexPool vertices;
  EdgePool edges;
  FacePool faces;
  Column<Vec3> points;
  Column<OrientedEdge> face_edges;
  ChangeStamps point_changes;      // ranges only: a point's element stamp is its edge's
  ChangeStamps face_edge_changes;  // ranges only: a loop's element stamp is its face's

  // ---- reading
  size_t vertex_slots() const { return vertices.flags.size(); }
  size_t edge_slots() const { return edges.flags.size(); }
  size_t face_slots() const { return faces.flags.size(); }
  bool vertex_alive(VertexIndex v) const { return v < vertex_slots() && (vertices.flags[v] & kAlive); }
  bool edge_alive(EdgeIndex e) const { return e < edge_slots() && (edges.flags[e] & kAlive); }
  bool face_alive(FaceIndex f) const { return f < face_slots() && (faces.flags[f] & kAlive); }
  size_t vertex_count() const;
  size_t edge_count() const;
  size_t face_count() const;
  size_t live_point_count() const;  // points owned by live edges (shared ends counted per edge)

  VertexId vertex_id(VertexIndex v) const { return {v, vertices.generation[v]}; }
  EdgeId edge_id(EdgeIndex e) const { return {e, edges.generation[e]}; }
  FaceId face_id(FaceIndex f) const { return {f, faces.generation[f]}; }
  bool valid(VertexId h) const { return vertex_alive(VertexIndex{h.index}) && vertices.generation[h.index] == h.generation; }
  bool valid(EdgeId h) const { return edge_alive(EdgeIndex{h.index}) && edges.generation[h.index] == h.generation; }
  bool valid(FaceId h) const { return face_alive(FaceIndex{h.index}) && faces.generation[h.index] == h.generation; }

  std::span<const Vec3> polyline(EdgeIndex e) const {
    return points.span(edges.point_offset[e], edges.point_count[e]);
  }
  std::span<const OrientedEdge> face_loop(FaceIndex f) const {
    return face_edges.span(faces.edge_offset[f], faces.edge_count[f]);
  }
  // The vertex an oriented edge starts from / arrives at when its face walks it.
  VertexIndex tail(OrientedEdge oriented) const {
    return VertexIndex{edges.vertex[edge_of(oriented)][is_reversed(oriented) ? 1 : 0]};
  }
  VertexIndex head(OrientedEdge oriented) const {
    return VertexIndex{edges.vertex[edge_of(oriented)][is_reversed(oriented) ? 0 : 1]};
  }
  // Edges incident to v (unordered).
  std::vector<EdgeIndex> vertex_edges(VertexIndex v) const;
  uint32_t valence(VertexIndex v) const;
  // The other face of an edge, or kNone.
  FaceIndex other_face(EdgeIndex e, FaceIndex f) const {
    const auto& fs = edges.face[e];
    return FaceIndex{fs[0] == f ? fs[1] : fs[0]};
  }
  bool is_border_edge(EdgeIndex e) const { return edges.face[e][0] == kNone || edges.face[e][1] == kNone; }
  // An edge with no face on either side: a curve of a border polygon still being drawn.
  bool is_loose_edge(EdgeIndex e) const { return edges.face[e][0] == kNone && edges.face[e][1] == kNone; }
  // A bridge (kBridgeEdge) still waiting for the second curve between its two border loops.
  bool is_waiting_bridge(EdgeIndex e) const { return is_loose_edge(e) && (edges.flags[e] & kBridgeEdge); }
  bool is_pending(EdgeIndex e) const { return edges.flags[e] & kPendingEdge; }
  // The pending chains (kPendingEdge), each as its pieces in drawing order (edge i ends where i + 1 starts):
  // the first starts on the network where the chain began, the last ends at the chain's free end.
  std::vector<std::vector<EdgeIndex>> pending_chains() const;
  // Pieces of pending chains (kPendingEdge), without walking them.
  size_t pending_piece_count() const;
  // The oriented edge that walks border edge e as the hole beside it would: against its one face.
  OrientedEdge hole_side(EdgeIndex e) const { return make_oriented(e, edges.face[e][1] == kNone); }
  // The border loop through border edge e as the hole beside it walks it, starting with e; empty when e has
  // not exactly one face, or the loop passes a vertex with more than two border curves (it pinches there).
  std::vector<OrientedEdge> border_loop(EdgeIndex e) const;
  // Whether a border polygon is being drawn: some live edge other than a bridge has no face yet.
  bool border_in_progress() const;
  // Bridges (kBridgeEdge) still waiting for the second curve between their two border loops.
  size_t pending_bridge_count() const;
  // The border loops of the faces (what Mesh::border_loop walks; a loop through a pinched vertex is not counted).
  size_t border_loop_count() const;
  // Index of edge e in f's loop, or kNone.
  uint32_t loop_position(FaceIndex f, EdgeIndex e) const;
  // Face f's boundary as one closed polyline in loop order, each corner once (the last point is not the first).
  std::vector<Vec3> face_boundary(FaceIndex f) const;

  // ---- frames and change stamps
  // Every write from now on is stamped `f`; frames never go back.
  void begin_frame(Frame f);
  Frame frame() const { return frame_; }
  const CompactionRecord& last_compaction() const { return last_compaction_; }
  // Whether any vertex, edge or face was written after frame `f`.
  bool written_after(Frame f) const;

  // ---- primitive mutations (journaled inside a transaction, stamped always)
  VertexIndex add_vertex(const Vec3& p, uint8_t extra_flags = 0);
  // The polyline must have at least 2 points; its ends are set to the vertices' positions exactly.
  EdgeIndex add_edge(VertexIndex v0, VertexIndex v1, std::span<const Vec3> polyline);
  // `loop` is a closed walk of oriented edges. Fails (returns kNone, changes nothing) when an edge's side
  // is already taken by another face or the walk is not closed.
  FaceIndex add_face(std::span<const OrientedEdge> loop);
  // Gives face f a new loop, keeping its slot and handle (used when an edge of f is split or joined).
  // Returns false and changes nothing when the loop is not closed or an edge side is taken by another face.
  bool set_face_loop(FaceIndex f, std::span<const OrientedEdge> loop);
  void remove_face(FaceIndex f);
  void remove_edge(EdgeIndex e);      // the edge must have no faces
  void remove_vertex(VertexIndex v);  // the vertex must have no edges
  void set_edge_flag(EdgeIndex e, uint8_t flag, bool on);
  // Moves a vertex and the matching end of every incident polyline.
  void move_vertex(VertexIndex v, const Vec3& p);

  // ---- transactions
  MeshMark begin_transaction();
  void end_transaction();
  // Restores the pools to `mark` (the most recent transaction not rolled back yet).
  void rollback(const MeshMark& mark);
  void forget_history();
  // Every column's size and journal length now: what begin_transaction() would return, without opening one.
  MeshMark journal_marks() const;

  // ---- sync point
  // Squeezes out dead slots, keeping each survivor's stamp, and records the map in last_compaction().
  // Forgets the undo history: call it only where no undo may reach back.
  const CompactionMap& compact();

  // ---- comparison, hashing
  // FNV-1a 64 over every pool column (sizes and bytes); stamps and journals excluded.
  uint64_t hash() const;
  bool same_pools(const Mesh& other) const;
  size_t pool_bytes() const;     // bytes held by the pools' arrays
  size_t journal_bytes() const;  // bytes held by the undo journals

  // ---- snapshots (engine/SESSION.md): every column with its undo journal, the change stamps, the frame
  // and the last compaction, so that a loaded mesh continues (undo included) bit for bit. Call between
  // frames, outside a transaction. load() fails on impossible sizes and leaves validate() to the caller.
  void save(SnapshotWriter& out) const;
  bool load(SnapshotReader& in);

  // ---- invariants (thesis 5.1 plus pool consistency); empty string when valid
  std::string validate() const;

 private:
  template <class F>
  void for_each_stamped_column(F&& f);
  template <class F>
  void for_each_column(F&& f);
  template <class F>
  void for_each_column(F&& f) const;
  uint32_t allocate(Column<uint32_t>& free_list, Column<uint32_t>& generation, Column<uint8_t>& flags,
                    ChangeStamps& changes);
  void release(uint32_t slot, Column<uint32_t>& free_list, Column<uint32_t>& generation, Column<uint8_t>& flags,
               ChangeStamps& changes);
  Frame frame_ = 0;
  CompactionRecord last_compaction_;
  void link_edge(EdgeIndex e);
  void unlink_edge(EdgeIndex e);
  // Whether `loop` is a closed walk of live edges, none twice, whose sides are free or already f's.
  bool loop_fits(std::span<const OrientedEdge> loop, FaceIndex f) const;
  // Names `face` (or kNone) on the side of each edge that the loop walks.
  void set_loop_sides(std::span<const OrientedEdge> loop, FaceIndex face);
  // Appends the loop to face_edges for `face`, naming it on the edges; returns the loop's offset.
  uint32_t append_loop(std::span<const OrientedEdge> loop, FaceIndex face);
};

struct MeshMark {
  std::vector<ColumnMark> columns;
};

}  // namespace fire
