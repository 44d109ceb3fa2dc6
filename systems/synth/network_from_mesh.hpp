#pragma once
// Synthetic curve networks from a polygon control mesh (thesis chapter 7): unrefine the mesh by dropping
// edge loops, turn each chain of kept edges into one polyline edge, collapse interior vertices of
// valence 2 (thesis figure 63; a vertex stays where collapsing it would leave a face with fewer than 3
// sides, which the thesis's reconstruction cannot take) and add seeded Gaussian noise to the polylines.
#include <cstdint>
#include <span>
#include <vector>

#include "engine/common.hpp"
#include "engine/mesh.hpp"
#include "engine/polygon_mesh.hpp"

namespace fire {

struct UnrefineOptions {
  uint32_t unrefine = 1;          // keep every K-th edge loop, counted from the border and creases (always kept); 1 keeps every edge
  double noise_percent = 0;       // Gaussian sigma, in percent of the mean control edge length
  // Correlation length of the noise along each polyline, in percent of the mean control edge length; 0
  // draws every point's noise independently.
  double noise_correlation_percent = 0;
  uint64_t seed = 0;              // seeds the noise
  uint32_t samples_per_edge = 8;  // polyline points each control edge contributes (at least 8)
  // Sample the control mesh's Catmull-Clark limit surface instead of its straight edges: vertices sit at
  // their limit positions and each control edge contributes the limit positions of the level-L vertices
  // on it, 2^L >= samples_per_edge (so the network lies exactly on its ground truth).
  bool limit = false;
  // The control mesh's subdivision tags (platform/obj.hpp's SubdivisionTags): vertex pairs of infinitely sharp
  // creases, and border corners. The limit surface honours them, and a network curve whose control edges are
  // all creases is marked sharp.
  std::span<const uint32_t> sharp_edges = {};
  std::span<const uint8_t> border_corners = {};
};

inline constexpr uint32_t kMinSamplesPerEdge = 8;

// Builds the curve network. Errors (naming `control.source`): a non-manifold edge (more than 2 faces),
// inconsistent face orientation, bad indices or coordinates, options out of range, and an unrefinement so
// coarse that a merged region is not a disk. The result is compact and passes Mesh::validate().
Result<Mesh> network_from_mesh(const PolygonMeshView& control, const UnrefineOptions& options);

// The control mesh's Catmull-Clark limit surface as quads: the level-`levels` mesh with every vertex at its
// limit position. What the simulated cameras see the object as.
Result<PolygonMesh> limit_mesh(const PolygonMeshView& control, int levels, std::span<const uint32_t> sharp_edges = {},
                               std::span<const uint8_t> border_corners = {});

// The polyline of one chain of control vertices: each control edge contributes `samples_per_edge` points
// spaced linearly from its first end (inclusive) to its second (exclusive), then the chain's last vertex.
// Appends chain_size-1 times samples_per_edge plus one points to `out`.
void sample_chain_linear(std::span<const Vec3> positions, std::span<const uint32_t> chain,
                         uint32_t samples_per_edge, std::vector<Vec3>& out);

}  // namespace fire

namespace fire {

// Points along every control edge on the Catmull-Clark limit surface (EdgeAndCorner boundaries).
class LimitCurves {
 public:
  // samples_per_edge is rounded up to a power of two 2^L; the control mesh is refined L levels.
  static Result<LimitCurves> build(const PolygonMeshView& control, uint32_t samples_per_edge, std::span<const uint32_t> sharp_edges = {},
                                   std::span<const uint8_t> border_corners = {});
  // Limit position of control vertex v.
  const Vec3& vertex(uint32_t v) const { return limit_[last_of_base_[v]]; }
  // Like sample_chain_linear, on the limit surface: 2^L points per control edge, then the last vertex.
  // Returns false if two consecutive chain vertices are not joined by a control edge.
  bool sample_chain(std::span<const uint32_t> chain, std::vector<Vec3>& out) const;

 private:
  std::vector<Vec3> limit_;                     // limit positions of the last level's vertices
  std::vector<std::vector<uint32_t>> along_;    // per base edge: last-level vertices from its first to second vertex (exclusive)
  std::vector<std::pair<uint64_t, uint32_t>> edge_by_ends_;  // sorted (min << 32 | max) -> base edge
  std::vector<uint32_t> base_edge_vertices_;
  std::vector<uint32_t> last_of_base_;  // per control vertex: its last-level vertex
};

}  // namespace fire
