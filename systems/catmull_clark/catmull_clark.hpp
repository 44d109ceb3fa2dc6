#pragma once
// Catmull-Clark subdivision equal to OpenSubdiv's Catmark scheme with boundary interpolation
// EdgeAndCorner (boundary edges are infinitely sharp, boundary vertices with one face are corners; or
// the border's corners given per vertex, BaseTopology::border_corners),
// infinitely sharp creases, faces of any size and vertices of any valence.
//
// Topology lives in flat index arrays per level. Refinement from level l to l+1 is given by
// parent-to-child index maps (implicit, see below) and stencils: each child vertex is a weighted sum
// of parent points. The stencils are stored in the structure the scheme gives them: a face point's
// sources are its face's vertices, an edge point's its edge's ends and faces, a vertex point's its
// ring (ring_neighbors and ring_corners), and the weights follow from the vertex rule and valence.
// evaluate() applies them level by level, so moving the base points re-evaluates every level without
// touching topology. stencil_table() writes the same stencils out as explicit (source, weight) rows and
// factorize() composes them into last-level-from-base rows (for solvers that need the matrix); applying
// those is slower than evaluate() (perf/notes/subdivide.md has the figures).
//
// Child components follow OpenSubdiv's uniform ordering (Vtr::Refinement with
// orderVerticesFromFacesFirst = false), so level l of a Refinement has the same vertex, edge and
// face numbering as level l of a Far::TopologyRefiner built from the same faces, except for the last
// level's vertices where the refinement has regular patches (RegularPatches below; the faces and edges
// keep their numbers, and Refinement::last_from_osd maps the vertices):
//   child vertices: parent vertex v -> v, parent face f -> V + f, parent edge e -> V + F + e;
//   child faces:    face f gets one quad per corner; the quad of corner c (global corner index) is c;
//   child edges:    corner c of face f gives the interior edge c (face point to edge point of the edge
//                   leaving corner c); parent edge e gives edges C + 2e + k, k = 0,1 (edge point to the
//                   child of edge_vertices[2e + k]);  V, F, E, C = parent vertex, face, edge, corner counts.
#include <cstdint>
#include <span>
#include <vector>

#include "engine/common.hpp"
#include "engine/polygon_mesh.hpp"

namespace fire::catmull_clark {

// The rule that moves a vertex, from its count of infinitely sharp incident edges (boundary edges
// included): 0 smooth, 1 dart (moves like smooth), 2 crease, more than 2 corner. A boundary vertex with
// a single face and a vertex with no face are corners.
enum class VertexRule : uint8_t { Smooth, Dart, Crease, Corner };

// The base mesh as plain arrays: face f uses face_vertices[face_offsets[f] .. face_offsets[f+1]),
// counter-clockwise seen from outside; sharp_edges holds vertex index pairs (a0, b0, a1, b1, ...) of
// edges that are infinitely sharp creases. border_corners, when given (one flag per vertex), says which
// boundary vertices are corners instead of EdgeAndCorner's rule: a flagged boundary vertex is a corner,
// an unflagged one with a single face is a smooth point of its border (the crease rule along it); flags
// of interior vertices are ignored.
struct BaseTopology {
  uint32_t vertex_count = 0;
  std::span<const uint32_t> face_offsets;
  std::span<const uint32_t> face_vertices;
  std::span<const uint32_t> sharp_edges;
  std::span<const uint8_t> border_corners = {};
};

// One level's topology. A "corner" is one entry of face_vertices; corner c of face f lies in
// [face_offsets[f], face_offsets[f+1]). Only face_offsets and face_vertices are filled in a last level
// built without adjacency (RefinementOptions::last_level_adjacency = false).
struct Level : PolygonFaces<uint32_t> {
  uint32_t vertex_count = 0;
  std::vector<uint32_t> face_edges;       // per corner: the edge from this corner to the next one
  std::vector<uint32_t> corner_faces;     // per corner: its face; level 0 only (later levels: corner / 4)

  std::vector<uint32_t> edge_vertices;  // 2 per edge (OpenSubdiv's order)
  std::vector<uint32_t> edge_corners;   // 2 per edge: the corner it leaves in each face; 2nd kNone on a boundary
  std::vector<uint8_t> edge_sharp;      // 1 for infinitely sharp (boundary or marked) edges

  // The one-ring of vertex v, counter-clockwise: ring slots ring_offsets[v] .. ring_offsets[v+1], one
  // per incident edge. Slot i holds edge i, the vertex at its other end, and the corner of v in the
  // face that lies between edge i and edge i+1 (edge i leaves v in that face). On a boundary vertex
  // slot 0 holds the leading boundary edge and the last slot the trailing one, whose corner is kNone.
  // The first slot of an interior vertex is the one OpenSubdiv starts with (it decides the side a
  // crease's limit normal is taken on).
  std::vector<uint32_t> ring_offsets;  // vertex count + 1
  std::vector<uint32_t> ring_edges;
  std::vector<uint32_t> ring_neighbors;
  std::vector<uint32_t> ring_corners;
  std::vector<VertexRule> vertex_rules;

  uint32_t corner_count() const { return static_cast<uint32_t>(face_vertices.size()); }
  uint32_t edge_count() const { return static_cast<uint32_t>(edge_vertices.size() / 2); }
  bool has_adjacency() const { return !ring_offsets.empty(); }
  uint32_t corner_face(uint32_t corner) const { return corner_faces.empty() ? corner >> 2 : corner_faces[corner]; }
  // Face `side` (0 or 1) of edge e; kNone for side 1 of a boundary edge.
  uint32_t edge_face(uint32_t e, uint32_t side) const {
    const uint32_t corner = edge_corners[2 * e + side];
    return corner == kNone ? kNone : corner_face(corner);
  }
};

// Sparse rows in CSR form: row r is the sum over k in [offsets[r], offsets[r+1]) of
// weights[k] * point[sources[k]].
struct StencilTable {
  std::vector<uint32_t> offsets{0};
  std::vector<uint32_t> sources;
  std::vector<double> weights;
  uint32_t row_count() const { return static_cast<uint32_t>(offsets.size() - 1); }
};

struct RefinementOptions {
  int levels = 1;  // 0 .. kMaxRefinementLevels
  // The last level's edges and rings, needed for build_limit_stencils; without them only its faces are
  // built (what Far::TopologyRefiner builds by default).
  bool last_level_adjacency = true;
};
inline constexpr int kMaxRefinementLevels = 10;

// Regular patches, for kMinPatchLevels to kMaxPatchLevels levels. A base quad whose corners are
// smooth, of valence 4 and surrounded by quads stays a regular grid at every level (a uniform bicubic
// B-spline patch): each of its last-level points is a fixed tensor product of 1D weights over the 4x4
// base points around it, so evaluate() computes it straight from them, with no intermediate levels and
// no index arrays. The other faces, with every face that shares a vertex with them (the base points
// their last-level points depend on), form a mesh of their own (`rest`) that the level-by-level path
// refines.
//
// Where a refinement has regular patches, its last level is numbered in the order evaluate() writes
// it, so that every write is sequential (with OpenSubdiv's numbering the points of one patch are spread
// over the whole level, and those scattered writes cost more than the arithmetic; perf/notes/subdivide.md):
// patch after patch, each patch's grid points row by row, leaving out the points on its sides and
// corners that an earlier patch has; then the points only the rest mesh has, in rest_sources order.
inline constexpr int kMinPatchLevels = 3, kMaxPatchLevels = 6;
inline constexpr uint32_t kMaxPatchSide = (1u << kMaxPatchLevels) + 1;
struct RegularPatches {
  uint32_t side = 0;                    // last-level points per patch side: 2^levels + 1
  std::vector<double> weights;          // 4 x side: the 1D weights of the points along a side over
                                        // 4 base points, base point by base point
  std::vector<uint32_t> controls;       // 16 base vertices per patch, 4 rows of 4; patch p's grid
                                        // point (u, v) (u along its first edge) lies in the square of
                                        // controls (u, v) .. (u+1, v+1) scaled by side - 1
  std::vector<uint8_t> owned;           // per patch: bit k set if it writes the points on its side k
                                        // (0: v = 0, 1: u = side-1, 2: v = side-1, 3: u = 0), bit 4+k
                                        // if it writes corner k ((0,0), (side-1,0), (side-1,side-1), (0,side-1))
  std::vector<Level> rest;              // the mesh of the other faces, refined (empty if there are none)
  std::vector<uint32_t> rest_controls;  // base vertex of each base vertex of `rest`
  std::vector<uint32_t> rest_sources;   // the last-level vertex of `rest` of each last-level vertex
                                        // after the patches' points, in order
  uint32_t patch_count() const { return static_cast<uint32_t>(controls.size() / 16); }
};

struct Refinement {
  std::vector<Level> levels;  // levels[0] is the base mesh
  RegularPatches patches;     // empty where evaluate() goes level by level
  // The last-level vertex of each vertex of OpenSubdiv's last level; empty where the two numberings are
  // the same (no regular patches).
  std::vector<uint32_t> last_from_osd;
  const Level& last() const { return levels.back(); }
};

// The last-level vertex that vertex v of an earlier level becomes (in OpenSubdiv's numbering a vertex
// keeps its index at every later level).
inline uint32_t last_level_vertex(const Refinement& refinement, uint32_t v) {
  return refinement.last_from_osd.empty() ? v : refinement.last_from_osd[v];
}

// Faces of level `level` (at least 1) of a mesh with `base_corners` face corners: one quad per corner at
// level 1, four children per face after that.
inline uint64_t faces_at_level(uint64_t base_corners, int level) { return base_corners << (2 * (level - 1)); }

// Builds the levels. Errors name the offending face, edge or vertex: a face with fewer
// than 3 vertices or a repeated vertex, an index out of range, an edge shared by more than 2 faces or
// twice in the same direction (inconsistent orientation), a vertex whose faces do not form one fan,
// a sharp edge that is not an edge, a refinement too large for 32-bit indices.
Result<Refinement> build_refinement(const BaseTopology& base, const RefinementOptions& options);

// Points of the last level from base points (one per base vertex): by regular patches where the
// refinement has them, else level by level. scratch holds intermediate points (pass the same vectors
// again to avoid allocations; base_points must not alias either).
void evaluate(const Refinement& refinement, std::span<const Vec3> base_points, std::vector<Vec3>& last_level_points,
              std::vector<Vec3>& scratch);

// Points of every level, level by level (the last level in its own numbering; from regular patches,
// evaluate() can differ from it in the last bits): level_points[0] is a copy of base_points.
void evaluate_all_levels(const Refinement& refinement, std::span<const Vec3> base_points,
                         std::vector<std::vector<Vec3>>& level_points);

// Level `level`'s points -> level `level + 1`'s points as explicit rows (level < levels.size() - 1), in
// level `level + 1`'s numbering. With `rows` (one flag per row), only the flagged rows are written and
// the others are left empty: a composition that reads a few rows need not build them all.
StencilTable stencil_table(const Refinement& refinement, size_t level, std::span<const uint8_t> rows = {});

// dst[r] = row r of table applied to src (dst.size() == table.row_count()).
void apply(const StencilTable& table, std::span<const Vec3> src, std::span<Vec3> dst);

// outer applied after inner, as one table (rows of outer, sources of inner).
StencilTable compose(const StencilTable& outer, const StencilTable& inner);

// All levels' stencils composed: last-level points straight from base points.
StencilTable factorize(const Refinement& refinement);

// Limit masks of the last level's vertices (Catmull-Clark limit position and two limit tangents per
// vertex, with OpenSubdiv's smooth, crease and corner masks), as rows over last-level points.
struct LimitStencils {
  std::vector<uint32_t> offsets{0};
  std::vector<uint32_t> sources;
  std::vector<double> position;
  std::vector<double> tangent1;
  std::vector<double> tangent2;
};

// Requires a last level with adjacency whose faces are all quads (true after one refinement).
Result<LimitStencils> build_limit_stencils(const Refinement& refinement);
// The same into `limit`, reusing its buffers (a frame that rebuilds topology then takes no fresh pages).
Status build_limit_stencils(const Refinement& refinement, LimitStencils& limit);

// Limit positions and unit normals (tangent1 x tangent2, zero where the tangents are parallel or the
// vertex has no face) of the last level's vertices, from the last level's points.
void evaluate_limit(const LimitStencils& limit, std::span<const Vec3> last_level_points, std::vector<Vec3>& positions,
                    std::vector<Vec3>& normals);

// The last-level vertices lying on edge `edge` of level `level`, in order from its end `from`, without the
// far end (child vertices keep their parent's index, so this follows the child-edge numbering above).
void vertices_along_edge(const Refinement& refinement, size_t level, uint32_t edge, uint32_t from,
                         std::vector<uint32_t>& out);

// One call from a polygon mesh to its subdivided quads and limit surface samples.
struct SubdivisionInput {
  PolygonMeshView mesh;
  std::span<const uint32_t> sharp_edges;
  std::span<const uint8_t> border_corners = {};  // as BaseTopology's
};
struct SubdividedMesh {
  std::vector<Vec3> positions;         // last level points
  std::vector<uint32_t> quads;         // 4 per face
  std::vector<Vec3> limit_positions;   // per vertex of the last level
  std::vector<Vec3> limit_normals;
};
// levels >= 1. Rejects non-finite positions besides what build_refinement rejects.
Result<SubdividedMesh> subdivide(const SubdivisionInput& input, int levels);

}  // namespace fire::catmull_clark
