#pragma once
// The per-edge and per-face stages of reconstruction. Each is a pure function of one network edge or
// one network face (its loop and its edges' polylines), which is what lets an edit recompute only the
// faces it touched: both faces of an edge split it identically because the split is computed on the
// edge's stored polyline, never on a face's view of it.
#include <bit>
#include <cstdint>
#include <span>
#include <vector>

#include "engine/mesh.hpp"
#include "engine/polygon_mesh.hpp"
#include "systems/reconstruct/geometry.hpp"

namespace fire::reconstruct {

enum class Method : uint8_t { Thesis, Fire };

// A base-mesh vertex before global numbering: a network vertex (index = vertex slot), a split point of a
// network edge (index = edge slot, sub = 1 .. 2^N - 1 along the edge's stored direction), or a vertex made
// inside a face (index = its position in FacePatch::interior).
enum class RefKind : uint8_t { NetworkVertex, EdgePoint, Interior };
struct VertexRef {
  RefKind kind = RefKind::NetworkVertex;
  uint32_t index = 0;
  uint32_t sub = 0;
  friend bool operator==(const VertexRef&, const VertexRef&) = default;
};

// A network edge's polyline split recursively at middle samples, `depth` times. Heap order: node 1 is the
// whole polyline, the halves of node k are 2k and 2k+1, and the leaves 2^depth .. 2^(depth+1)-1 are the
// base edges along the network edge, in its stored direction.
struct EdgeSplits {
  uint32_t depth = 0;
  std::vector<std::vector<Vec3>> nodes;
  std::span<const Vec3> node(uint32_t k) const { return nodes[k]; }
  uint32_t leaf_count() const { return 1u << depth; }
  std::span<const Vec3> leaf(uint32_t i) const { return nodes[leaf_count() + i]; }
  // The leaves below node k: the first one's index and how many.
  uint32_t first_leaf(uint32_t k) const { return (k << (depth - level(k))) - leaf_count(); }
  uint32_t leaves_below(uint32_t k) const { return 1u << (depth - level(k)); }
  static uint32_t level(uint32_t k) { return static_cast<uint32_t>(std::bit_width(k)) - 1; }
};
EdgeSplits split_network_edge(std::span<const Vec3> line, uint32_t depth);

struct FaceSettings {
  Method method = Method::Fire;
  uint32_t coons_steps = 1;
  Planarity planarity = Planarity::LeastSquares;
};

// What one network face contributes to the base mesh. Its faces (PolygonFaces) are the base faces, corners in
// the face's winding: quads, or polygons where a side is split more finely than the face's Coons steps (its
// edge's EdgeSplits::depth), whose finer split points lie between them.
struct FacePatch : PolygonFaces<VertexRef> {
  std::vector<Vec3> interior;       // positions of the vertices made inside the face
  // Base edges inside the face (triquadrification cuts, spokes) with the polylines they carry: straight
  // (thesis) or sampled from the transfinite patch (FIRE). 2 ends per curve.
  std::vector<VertexRef> curve_ends;
  std::vector<uint32_t> curve_offsets{0};
  std::vector<Vec3> curve_points;
  uint32_t curve_count() const { return static_cast<uint32_t>(curve_offsets.size() - 1); }
  std::span<const Vec3> curve(uint32_t c) const {
    return std::span<const Vec3>(curve_points).subspan(curve_offsets[c], curve_offsets[c + 1] - curve_offsets[c]);
  }
  // Sizes of the faces the first stage made: the triquadrification's triangles and quads (thesis), or
  // the face itself (FIRE).
  std::vector<uint32_t> first_stage_sizes;
};

// One side of a face: a network edge, or a chain of them joined through network vertices the surface
// leaves out (reconstruct.cpp), from network vertex `from` to `to` in its stored direction.
struct FaceSide {
  const EdgeSplits* splits = nullptr;  // depth >= coons_steps, one less for a half of a joined side
  uint32_t network_edge = 0;           // the edge slot its split points are named by (VertexRef::index)
  uint32_t from = 0, to = 0;
  bool reversed = false;  // the face's loop walks it from `to` to `from`
  double length = 0;      // its drawn polyline's length and segments: the face's sample spacing
  size_t segments = 0;
  // FIRE: the loop goes straight on through the corner between this side and the next, so the two are
  // one side of the face, split first at that corner and then each along its own split (the next side
  // does not join the one after it).
  bool joins_next = false;
};

// The face's sides in loop order. A face with 2 sides is the degenerate quad whose other two sides are
// its corners: 2 quads around the centre of the ruled surface between its two curves (FIRE's rule; the
// thesis has none, and check_reconstruction_input rejects such faces for it).
FacePatch build_face_patch(std::span<const FaceSide> sides, const FaceSettings& settings);
// The same for network face `face` whose every edge is a side: `splits[k]` is the split of the edge at
// loop position k.
FacePatch build_face_patch(const Mesh& net, uint32_t face, std::span<const EdgeSplits* const> splits,
                           const FaceSettings& settings);

}  // namespace fire::reconstruct
