#include "systems/reconstruct/face.hpp"

#include "engine/assert.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <map>

namespace fire::reconstruct {

EdgeSplits split_network_edge(std::span<const Vec3> line, uint32_t depth) {
  EdgeSplits s;
  s.depth = depth;
  s.nodes.resize(size_t(2) << depth);  // slot 0 unused
  s.nodes[1].assign(line.begin(), line.end());
  for (uint32_t k = 1; k < (1u << depth); ++k) split_polyline(s.nodes[k], s.nodes[2 * k], s.nodes[2 * k + 1]);
  return s;
}

namespace {

struct LocalEdge {
  VertexRef from, to;
  std::vector<Vec3> own;               // the polyline of an edge made inside the face
  const EdgeSplits* splits = nullptr;  // or a piece of a network edge: node `node` of its split
  uint32_t network_edge = kNone;
  uint32_t node = 0;
  std::vector<double> params;
  int32_t first_child = -1;  // the halves, once split: first_child (from -> mid), first_child + 1
  std::array<bool, 2> child_reversed{false, false};  // a half stored against this edge's direction
  VertexRef mid;              // the split point
  Vec3 mid_point = Vec3::Zero();
  double mid_param = 0.5;    // arc parameter of the split point along the stored direction
  std::span<const Vec3> line() const { return splits ? splits->node(node) : std::span<const Vec3>(own); }
};

// The polyline mesh of one network face while it is being refined. Oriented edges as in the engine:
// local edge << 1 | reversed.
class LocalMesh {
 public:
  std::vector<LocalEdge> edges;
  std::vector<Vec3> interior;

  VertexRef add_interior(const Vec3& p) {
    interior.push_back(p);
    return {RefKind::Interior, static_cast<uint32_t>(interior.size() - 1), 0};
  }
  uint32_t add_edge(LocalEdge edge) {
    edges.push_back(std::move(edge));
    return static_cast<uint32_t>(edges.size() - 1);
  }
  VertexRef tail(uint32_t oe) const { return (oe & 1) ? edges[oe >> 1].to : edges[oe >> 1].from; }
  Vec3 tail_position(uint32_t oe) const {
    auto line = edges[oe >> 1].line();
    return (oe & 1) ? line.back() : line.front();
  }
  const std::vector<double>& params(uint32_t e) {
    LocalEdge& edge = edges[e];
    if (edge.params.empty()) edge.params = arc_parameters(edge.line());
    return edge.params;
  }
  Side side(uint32_t oe) {
    const std::vector<double>& p = params(oe >> 1);
    return Side{edges[oe >> 1].line(), p, (oe & 1) != 0};
  }

  void split(uint32_t e) {
    if (edges[e].first_child >= 0) return;
    LocalEdge first, second;
    const VertexRef from = edges[e].from, to = edges[e].to;
    VertexRef mid;
    if (const EdgeSplits* s = edges[e].splits) {
      const uint32_t k = edges[e].node;
      mid = {RefKind::EdgePoint, edges[e].network_edge, s->first_leaf(k) + s->leaves_below(k) / 2};
      first.splits = second.splits = s;
      first.network_edge = second.network_edge = edges[e].network_edge;
      first.node = 2 * k;
      second.node = 2 * k + 1;
    } else {
      split_polyline(edges[e].own, first.own, second.own);
      mid = add_interior(first.own.back());
    }
    first.from = from;
    first.to = mid;
    second.from = mid;
    second.to = to;
    const double whole = polyline_length(edges[e].line());
    const double part = polyline_length(first.line());
    const double mid_param = whole > 0 ? part / whole : 0.5;
    const Vec3 mid_point = first.line().back();
    const uint32_t c = add_edge(std::move(first));
    add_edge(std::move(second));
    edges[e].first_child = static_cast<int32_t>(c);
    edges[e].mid = mid;
    edges[e].mid_point = mid_point;
    edges[e].mid_param = mid_param;
  }
  // One edge made of two network sides walked in turn (oriented edges `a` then `b`, made just before
  // it, one after the other), already split at the corner between them.
  uint32_t join(uint32_t a, uint32_t b) {
    FIRE_ASSERT((a >> 1) + 1 == (b >> 1), "the halves of a joined side are made one after the other");
    LocalEdge whole;
    whole.from = tail(a);
    whole.to = tail(b ^ 1u);
    auto walked = [](std::span<const Vec3> line, bool reversed) {
      std::vector<Vec3> out(line.begin(), line.end());
      if (reversed) std::reverse(out.begin(), out.end());
      return out;
    };
    const std::vector<Vec3> first = walked(edges[a >> 1].line(), a & 1), second = walked(edges[b >> 1].line(), b & 1);
    whole.own = first;
    whole.own.insert(whole.own.end(), second.begin() + 1, second.end());
    whole.first_child = static_cast<int32_t>(a >> 1);
    whole.child_reversed = {(a & 1) != 0, (b & 1) != 0};
    whole.mid = tail(b);
    whole.mid_point = first.back();
    const double part = polyline_length(first), rest = polyline_length(second);
    whole.mid_param = part + rest > 0 ? part / (part + rest) : 0.5;
    return add_edge(std::move(whole));
  }
  // The half of a split edge that the walk meets first, and the other one, as oriented edges.
  uint32_t first_half(uint32_t oe) const { return (oe & 1) ? half(oe, 1) ^ 1u : half(oe, 0); }
  uint32_t second_half(uint32_t oe) const { return (oe & 1) ? half(oe, 0) ^ 1u : half(oe, 1); }
  // Half i of a split edge, oriented along it.
  uint32_t half(uint32_t oe, uint32_t i) const {
    const LocalEdge& edge = edges[oe >> 1];
    return (static_cast<uint32_t>(edge.first_child) + i) << 1 | (edge.child_reversed[i] ? 1u : 0u);
  }
  // The split points of a network edge's piece below the face's own steps, in walk order.
  void append_finer_points(uint32_t oe, std::vector<VertexRef>& out) const {
    const LocalEdge& edge = edges[oe >> 1];
    if (!edge.splits || edge.node >= edge.splits->leaf_count()) return;
    const uint32_t first = edge.splits->first_leaf(edge.node), span = edge.splits->leaves_below(edge.node);
    for (uint32_t i = 1; i < span; ++i)
      out.push_back({RefKind::EdgePoint, edge.network_edge, (oe & 1) ? first + span - i : first + i});
  }
  VertexRef mid(uint32_t oe) const { return edges[oe >> 1].mid; }
  Vec3 mid_position(uint32_t oe) const { return edges[oe >> 1].mid_point; }
  double mid_walk_param(uint32_t oe) const {
    const double t = edges[oe >> 1].mid_param;
    return (oe & 1) ? 1.0 - t : t;
  }
};

// Which rule makes the centre and the spokes of a face.
enum class Rule : uint8_t {
  ThesisCoons,     // thesis 6.2: Coons point x(1/2,1/2) and spokes x(1/2, j/2^R) with nearest samples
  ThesisCentroid,  // thesis 6.2 footnote: triangles use the centroid of the edge midpoints, straight spokes
  FireSided,       // FIRE first step: the n-sided patch (n >= 3) or the ruled surface of a 2-sided face
  FireCoons,       // FIRE later steps: bilinear Coons with linear sampling
};

struct Refiner {
  LocalMesh& mesh;
  double spacing;  // mean segment length of the network face's polylines: spokes are sampled as densely

  // A spoke of the last step is a base edge that nothing samples (the fit reads drawn curves only), so its
  // two ends are all it needs; the patch points along it were most of a big face's cost (perf/notes/frame.md,
  // "Refine's big faces"). Spokes of earlier steps are sides the next step's Coons patches sample.
  uint32_t spoke_segments(Rule rule, uint32_t remaining, const Vec3& from, const Vec3& to) const {
    const uint32_t needed = 1u << (remaining - 1);  // enough samples for the steps still to come
    if (rule == Rule::ThesisCoons || rule == Rule::ThesisCentroid || remaining == 1) return needed;
    const double dense = spacing > 0 ? std::round((to - from).norm() / spacing) : 1.0;
    return std::max(needed, static_cast<uint32_t>(std::clamp(dense, 1.0, 256.0)));
  }

  // Splits every side of the face, puts a centre vertex inside, joins it to the side midpoints with
  // spokes and returns the n quads (corner k: P_k, M_k, C, M_k-1).
  std::vector<std::vector<uint32_t>> refine(const std::vector<uint32_t>& loop, Rule rule, uint32_t remaining) {
    const uint32_t n = static_cast<uint32_t>(loop.size());
    for (uint32_t oe : loop) {
      mesh.split(oe >> 1);
      mesh.params(oe >> 1);
    }
    std::vector<Side> sides(n);
    for (uint32_t k = 0; k < n; ++k) sides[k] = mesh.side(loop[k]);
    std::vector<Vec3> mids(n);
    std::vector<double> t(n);
    for (uint32_t k = 0; k < n; ++k) {
      mids[k] = mesh.mid_position(loop[k]);
      t[k] = mesh.mid_walk_param(loop[k]);
    }

    // A 2-sided face is the degenerate quad whose sides 1 and 3 are its corners.
    const std::array<Vec3, 2> corner0{sides[0].start(), sides[0].start()};
    const std::array<Vec3, 2> corner1{sides[1].start(), sides[1].start()};
    const std::array<double, 2> constant_params{0.0, 1.0};
    std::vector<Side> quad_sides = sides;
    if (n == 2) quad_sides = {sides[0], Side{corner1, constant_params}, sides[1], Side{corner0, constant_params}};

    // Domain of the rule: centre, the end of each spoke and the evaluation.
    Eigen::Vector2d centre(0.5, 0.5);
    std::vector<Eigen::Vector2d> ends(n);
    const bool sided = rule == Rule::FireSided && n >= 3;
    if (sided) {
      centre = Eigen::Vector2d::Zero();
      for (uint32_t k = 0; k < n; ++k)
        ends[k] = domain_corner(n, k) + (domain_corner(n, k + 1) - domain_corner(n, k)) * t[k];
    } else if (rule == Rule::ThesisCoons) {
      ends = {Eigen::Vector2d(0.5, 0), Eigen::Vector2d(1, 0.5), Eigen::Vector2d(0.5, 1), Eigen::Vector2d(0, 0.5)};
    } else if (n == 2) {
      ends = {Eigen::Vector2d(t[0], 0), Eigen::Vector2d(1 - t[1], 1)};
    } else if (n == 4) {
      ends = {Eigen::Vector2d(t[0], 0), Eigen::Vector2d(1, t[1]), Eigen::Vector2d(1 - t[2], 1),
              Eigen::Vector2d(0, 1 - t[3])};
    }
    const Sampling sampling = rule == Rule::ThesisCoons ? Sampling::Nearest : Sampling::Linear;
    const SidedPatch patch(sided ? std::span<const Side>(sides) : std::span<const Side>());
    auto evaluate = [&](const Eigen::Vector2d& p) -> Vec3 {
      if (sided) return patch.at(p);
      return coons_point(quad_sides, p.x(), p.y(), sampling);
    };

    Vec3 c;
    if (rule == Rule::ThesisCentroid) {
      c = Vec3::Zero();
      for (const Vec3& m : mids) c += m;
      c /= double(n);
    } else {
      c = evaluate(centre);
    }
    std::vector<std::vector<Vec3>> spokes(n);
    for (uint32_t k = 0; k < n; ++k) {
      const uint32_t segments = spoke_segments(rule, remaining, c, mids[k]);
      if (rule == Rule::ThesisCentroid) {
        spokes[k] = straight_polyline(c, mids[k], segments);
        continue;
      }
      std::vector<Vec3>& line = spokes[k];
      line.resize(segments + 1);
      line.front() = c;
      line.back() = mids[k];
      for (uint32_t j = 1; j < segments; ++j) line[j] = evaluate(centre + (ends[k] - centre) * (double(j) / segments));
    }

    const VertexRef centre_ref = mesh.add_interior(c);
    std::vector<uint32_t> spoke(n);
    for (uint32_t k = 0; k < n; ++k) {
      LocalEdge e;
      e.from = centre_ref;
      e.to = mesh.mid(loop[k]);
      e.own = std::move(spokes[k]);
      spoke[k] = mesh.add_edge(std::move(e));
    }
    std::vector<std::vector<uint32_t>> quads(n);
    for (uint32_t k = 0; k < n; ++k) {
      const uint32_t before = (k + n - 1) % n;
      quads[k] = {mesh.first_half(loop[k]), spoke[k] << 1 | 1u, spoke[before] << 1, mesh.second_half(loop[before])};
    }
    return quads;
  }
};

}  // namespace

FacePatch build_face_patch(const Mesh& net, uint32_t face, std::span<const EdgeSplits* const> splits,
                           const FaceSettings& settings) {
  const auto network_loop = net.face_loop(FaceIndex{face});
  std::vector<FaceSide> sides(network_loop.size());
  for (size_t k = 0; k < sides.size(); ++k) {
    const EdgeIndex e = edge_of(network_loop[k]);
    sides[k] = {splits[k], e, net.edges.vertex[e][0], net.edges.vertex[e][1], is_reversed(network_loop[k]),
                polyline_length(net.polyline(e)), size_t(net.edges.point_count[e] - 1)};
  }
  return build_face_patch(sides, settings);
}

FacePatch build_face_patch(std::span<const FaceSide> sides, const FaceSettings& settings) {
  LocalMesh mesh;
  const uint32_t count = static_cast<uint32_t>(sides.size());
  auto add_side = [&](const FaceSide& side) {
    LocalEdge edge;
    edge.from = {RefKind::NetworkVertex, side.from, 0};
    edge.to = {RefKind::NetworkVertex, side.to, 0};
    edge.splits = side.splits;
    edge.network_edge = side.network_edge;
    edge.node = 1;
    return mesh.add_edge(std::move(edge)) << 1 | (side.reversed ? 1u : 0u);
  };
  // Start at a side that does not continue the one before it, so that joined pairs do not wrap round.
  uint32_t start = 0;
  while (start < count && sides[(start + count - 1) % count].joins_next) ++start;
  FIRE_ASSERT(start < count, "every side of a face joins the next");
  std::vector<uint32_t> loop;
  double total_length = 0;
  size_t total_segments = 0;
  for (uint32_t i = 0; i < count; ++i) {
    const FaceSide& side = sides[(start + i) % count];
    total_length += side.length;
    total_segments += side.segments;
    if (side.joins_next) {
      FIRE_ASSERT(i + 1 < count && !sides[(start + i + 1) % count].joins_next, "a side joins two others");
      const FaceSide& next = sides[(start + ++i) % count];
      total_length += next.length;
      total_segments += next.segments;
      const uint32_t a = add_side(side);
      loop.push_back(mesh.join(a, add_side(next)) << 1);
      continue;
    }
    loop.push_back(add_side(side));
  }
  const uint32_t n = static_cast<uint32_t>(loop.size());
  Refiner refiner{mesh, total_segments ? total_length / double(total_segments) : 0.0};

  FacePatch patch;
  const uint32_t steps = settings.coons_steps;
  std::vector<std::vector<uint32_t>> faces;
  if (settings.method == Method::Thesis && n >= 3) {
    if (n > 4) {
      std::vector<Vec3> corners(n);
      for (uint32_t k = 0; k < n; ++k) corners[k] = mesh.tail_position(loop[k]);
      std::map<std::pair<uint32_t, uint32_t>, uint32_t> cuts;  // corner pair -> local edge
      for (const std::vector<uint32_t>& polygon : triquadrify(corners, settings.planarity)) {
        std::vector<uint32_t> face_loop;
        for (size_t i = 0; i < polygon.size(); ++i) {
          const uint32_t a = polygon[i], b = polygon[(i + 1) % polygon.size()];
          if (b == (a + 1) % n) {
            face_loop.push_back(loop[a]);
            continue;
          }
          auto [it, fresh] = cuts.try_emplace({std::min(a, b), std::max(a, b)}, 0u);
          if (fresh) {
            // Thesis 6.1 / 7: a cut gets a straight polyline, as densely sampled as the face's curves.
            LocalEdge cut;
            cut.from = mesh.tail(loop[a]);
            cut.to = mesh.tail(loop[b]);
            const double length = (corners[b] - corners[a]).norm();
            const double segments = refiner.spacing > 0 ? std::round(length / refiner.spacing) : 1.0;
            cut.own = straight_polyline(corners[a], corners[b], static_cast<uint32_t>(std::clamp(segments, 1.0, 256.0)));
            it->second = mesh.add_edge(std::move(cut));
            face_loop.push_back(it->second << 1);
          } else {
            face_loop.push_back(it->second << 1 | 1u);
          }
        }
        faces.push_back(std::move(face_loop));
      }
    } else {
      faces.push_back(loop);
    }
    for (const auto& f : faces) patch.first_stage_sizes.push_back(static_cast<uint32_t>(f.size()));
    for (uint32_t step = 0; step < steps; ++step) {
      std::vector<std::vector<uint32_t>> refined;
      for (const auto& f : faces) {
        const Rule rule = f.size() == 3 ? Rule::ThesisCentroid : Rule::ThesisCoons;
        for (auto& q : refiner.refine(f, rule, steps - step)) refined.push_back(std::move(q));
      }
      faces = std::move(refined);
    }
  } else {
    patch.first_stage_sizes.push_back(n);
    faces = refiner.refine(loop, Rule::FireSided, steps);
    for (uint32_t step = 1; step < steps; ++step) {
      std::vector<std::vector<uint32_t>> refined;
      for (const auto& f : faces)
        for (auto& q : refiner.refine(f, Rule::FireCoons, steps - step)) refined.push_back(std::move(q));
      faces = std::move(refined);
    }
  }

  patch.interior = mesh.interior;
  for (const auto& f : faces) {
    for (uint32_t oe : f) {
      patch.face_vertices.push_back(mesh.tail(oe));
      mesh.append_finer_points(oe, patch.face_vertices);
    }
    patch.face_offsets.push_back(static_cast<uint32_t>(patch.face_vertices.size()));
  }
  for (const LocalEdge& e : mesh.edges) {
    if (e.splits || e.first_child >= 0) continue;
    patch.curve_ends.push_back(e.from);
    patch.curve_ends.push_back(e.to);
    patch.curve_points.insert(patch.curve_points.end(), e.own.begin(), e.own.end());
    patch.curve_offsets.push_back(static_cast<uint32_t>(patch.curve_points.size()));
  }
  return patch;
}

}  // namespace fire::reconstruct
