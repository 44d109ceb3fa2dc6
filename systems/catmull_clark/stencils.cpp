// Explicit stencil rows (the same weights evaluate() applies implicitly), their application and
// composition.
#include <algorithm>

#include "systems/catmull_clark/catmull_clark.hpp"

namespace fire::catmull_clark {
namespace {

class RowWriter {
 public:
  explicit RowWriter(const Level& level) : p_(level) {}

  uint32_t vertex_row_size(uint32_t v) const {
    switch (p_.vertex_rules[v]) {
      case VertexRule::Corner: return 1;
      case VertexRule::Crease: return 3;
      default: break;
    }
    const uint32_t r0 = p_.ring_offsets[v], r1 = p_.ring_offsets[v + 1];
    uint32_t size = 1 + (r1 - r0);
    for (uint32_t r = r0; r < r1; ++r) size += face_size(p_.corner_face(p_.ring_corners[r])) - 3;
    return size;
  }
  uint32_t edge_row_size(uint32_t e) const {
    if (p_.edge_sharp[e]) return 2;
    return 2 + (face_size(p_.edge_face(e, 0)) - 2) + (face_size(p_.edge_face(e, 1)) - 2);
  }

  void vertex_row(uint32_t v, uint32_t* src, double* w) const {
    const uint32_t r0 = p_.ring_offsets[v], n = p_.ring_offsets[v + 1] - r0;
    src[0] = v;
    switch (p_.vertex_rules[v]) {
      case VertexRule::Corner: w[0] = 1.0; return;
      case VertexRule::Crease: {
        w[0] = 0.75;
        uint32_t k = 1;
        for (uint32_t r = r0; k < 3; ++r) {
          if (!p_.edge_sharp[p_.ring_edges[r]]) continue;
          src[k] = p_.ring_neighbors[r];
          w[k++] = 0.125;
        }
        return;
      }
      default: break;
    }
    // Smooth and dart: (n-2)/n v + 1/n^2 (sum of edge neighbours + sum of face points), with the face
    // points expanded to the face's vertices (the vertex, its two ring neighbours and the others).
    const double edge_weight = 1.0 / (double(n) * n);
    w[0] = double(n - 2) / n;
    for (uint32_t i = 0; i < n; ++i) {
      src[1 + i] = p_.ring_neighbors[r0 + i];
      w[1 + i] = edge_weight;
    }
    uint32_t k = 1 + n;
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t corner = p_.ring_corners[r0 + i];
      const uint32_t f = p_.corner_face(corner), b = p_.face_offsets[f], m = face_size(f), j = corner - b;
      const double face_weight = edge_weight / m;
      w[0] += face_weight;
      w[1 + i] += face_weight;
      w[1 + (i + 1 == n ? 0 : i + 1)] += face_weight;
      for (uint32_t t = 2; t + 1 < m; ++t) {
        src[k] = p_.face_vertices[b + (j + t) % m];
        w[k++] = face_weight;
      }
    }
  }

  void edge_row(uint32_t e, uint32_t* src, double* w) const {
    src[0] = p_.edge_vertices[2 * e];
    src[1] = p_.edge_vertices[2 * e + 1];
    if (p_.edge_sharp[e]) {
      w[0] = w[1] = 0.5;
      return;
    }
    // 1/4 of each end plus 1/4 of each face point, the face points expanded to face vertices.
    w[0] = w[1] = 0.25;
    uint32_t k = 2;
    for (uint32_t side = 0; side < 2; ++side) {
      const uint32_t corner = p_.edge_corners[2 * e + side];
      const uint32_t f = p_.corner_face(corner), b = p_.face_offsets[f], m = face_size(f), j = corner - b;
      const double face_weight = 0.25 / m;
      w[0] += face_weight;
      w[1] += face_weight;
      for (uint32_t t = 2; t < m; ++t) {
        src[k] = p_.face_vertices[b + (j + t) % m];
        w[k++] = face_weight;
      }
    }
  }

  uint32_t face_size(uint32_t f) const { return p_.face_offsets[f + 1] - p_.face_offsets[f]; }

 private:
  const Level& p_;
};

}  // namespace

StencilTable stencil_table(const Refinement& refinement, size_t level, std::span<const uint8_t> rows) {
  const Level& p = refinement.levels.at(level);
  const uint32_t V = p.vertex_count, F = p.face_count(), E = p.edge_count();
  const RowWriter writer(p);
  // Child r in OpenSubdiv's numbering is row row_of(r): the same, except in a renumbered last level.
  const bool renumbered = level + 2 == refinement.levels.size() && !refinement.last_from_osd.empty();
  const auto row_of = [&](uint32_t r) { return renumbered ? refinement.last_from_osd[r] : r; };
  const auto wanted = [&](uint32_t row) { return rows.empty() || rows[row] != 0; };
  StencilTable table;
  table.offsets.assign(size_t{V} + F + E + 1, 0);
  for (uint32_t v = 0; v < V; ++v)
    if (wanted(row_of(v))) table.offsets[row_of(v) + 1] = writer.vertex_row_size(v);
  for (uint32_t f = 0; f < F; ++f)
    if (wanted(row_of(V + f))) table.offsets[row_of(V + f) + 1] = writer.face_size(f);
  for (uint32_t e = 0; e < E; ++e)
    if (wanted(row_of(V + F + e))) table.offsets[row_of(V + F + e) + 1] = writer.edge_row_size(e);
  for (size_t r = 1; r < table.offsets.size(); ++r) table.offsets[r] += table.offsets[r - 1];
  table.sources.resize(table.offsets.back());
  table.weights.resize(table.offsets.back());
  for (uint32_t v = 0; v < V; ++v) {
    if (!wanted(row_of(v))) continue;
    const uint32_t o = table.offsets[row_of(v)];
    writer.vertex_row(v, table.sources.data() + o, table.weights.data() + o);
  }
  for (uint32_t f = 0; f < F; ++f) {
    if (!wanted(row_of(V + f))) continue;
    const uint32_t b = p.face_offsets[f], n = writer.face_size(f), o = table.offsets[row_of(V + f)];
    for (uint32_t j = 0; j < n; ++j) {
      table.sources[o + j] = p.face_vertices[b + j];
      table.weights[o + j] = 1.0 / n;
    }
  }
  for (uint32_t e = 0; e < E; ++e) {
    if (!wanted(row_of(V + F + e))) continue;
    const uint32_t o = table.offsets[row_of(V + F + e)];
    writer.edge_row(e, table.sources.data() + o, table.weights.data() + o);
  }
  return table;
}

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 arrays are read as packed xyz triples");

void apply(const StencilTable& table, std::span<const Vec3> src, std::span<Vec3> dst) {
  const uint32_t rows = table.row_count();
  const uint32_t* offsets = table.offsets.data();
  const uint32_t* sources = table.sources.data();
  const double* weights = table.weights.data();
  const double* in = src.empty() ? nullptr : src.data()->data();
  double* out = dst.empty() ? nullptr : dst.data()->data();
  for (uint32_t r = 0; r < rows; ++r) {
    double x = 0, y = 0, z = 0;
    for (uint32_t k = offsets[r]; k < offsets[r + 1]; ++k) {
      const double* p = in + 3 * size_t{sources[k]};
      const double w = weights[k];
      x += w * p[0];
      y += w * p[1];
      z += w * p[2];
    }
    out[3 * size_t{r}] = x;
    out[3 * size_t{r} + 1] = y;
    out[3 * size_t{r} + 2] = z;
  }
}

StencilTable compose(const StencilTable& outer, const StencilTable& inner) {
  uint32_t source_count = 0;
  for (uint32_t s : inner.sources) source_count = std::max(source_count, s + 1);
  // slot[s]: where source s sits in the row being assembled, so repeated sources merge.
  std::vector<uint32_t> slot(source_count, kNone);
  StencilTable result;
  result.offsets.reserve(outer.offsets.size());
  for (uint32_t r = 0; r < outer.row_count(); ++r) {
    const size_t row_begin = result.sources.size();
    for (uint32_t k = outer.offsets[r]; k < outer.offsets[r + 1]; ++k) {
      const uint32_t mid = outer.sources[k];
      const double w = outer.weights[k];
      for (uint32_t t = inner.offsets[mid]; t < inner.offsets[mid + 1]; ++t) {
        const uint32_t s = inner.sources[t];
        if (slot[s] == kNone) {
          slot[s] = static_cast<uint32_t>(result.sources.size());
          result.sources.push_back(s);
          result.weights.push_back(w * inner.weights[t]);
        } else {
          result.weights[slot[s]] += w * inner.weights[t];
        }
      }
    }
    for (size_t k = row_begin; k < result.sources.size(); ++k) slot[result.sources[k]] = kNone;
    result.offsets.push_back(static_cast<uint32_t>(result.sources.size()));
  }
  return result;
}

StencilTable factorize(const Refinement& refinement) {
  if (refinement.levels.size() == 1) {
    StencilTable identity;
    const uint32_t n = refinement.levels[0].vertex_count;
    identity.offsets.resize(n + 1);
    identity.sources.resize(n);
    identity.weights.assign(n, 1.0);
    for (uint32_t v = 0; v <= n; ++v) identity.offsets[v] = v;
    for (uint32_t v = 0; v < n; ++v) identity.sources[v] = v;
    return identity;
  }
  StencilTable table = stencil_table(refinement, 0);
  for (size_t l = 1; l + 1 < refinement.levels.size(); ++l) table = compose(stencil_table(refinement, l), table);
  return table;
}

}  // namespace fire::catmull_clark
