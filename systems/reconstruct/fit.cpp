#include "systems/reconstruct/fit.hpp"

#include <Eigen/QR>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>

#include "engine/assert.hpp"

namespace fire::reconstruct {

namespace {

using SparseRows = Eigen::SparseMatrix<double, Eigen::RowMajor>;
using Sparse = Eigen::SparseMatrix<double>;


// The umbrella operator of the base mesh: each vertex minus the mean of its neighbours. On the border
// only the neighbours along the border count and the border's corners are left out, as Catmull-Clark
// treats them, so that a flat grid costs nothing up to its border.
Sparse umbrella(const BaseMesh& base) {
  const uint32_t n = base.vertex_count();
  std::unordered_map<uint64_t, uint32_t> sides;  // faces per undirected edge
  auto key = [](uint32_t a, uint32_t b) { return uint64_t(std::min(a, b)) << 32 | std::max(a, b); };
  std::vector<uint32_t> faces(n, 0);
  for (uint32_t f = 0; f < base.face_count(); ++f)
    for (uint32_t c = base.face_offsets[f]; c < base.face_offsets[f + 1]; ++c) {
      const uint32_t next = c + 1 == base.face_offsets[f + 1] ? base.face_offsets[f] : c + 1;
      ++sides[key(base.face_vertices[c], base.face_vertices[next])];
      ++faces[base.face_vertices[c]];
    }
  std::vector<std::vector<uint32_t>> all(n), border(n);
  for (uint32_t c = 0; c < base.curve_count(); ++c) {
    const uint32_t a = base.curve_ends[2 * c], b = base.curve_ends[2 * c + 1];
    all[a].push_back(b);
    all[b].push_back(a);
    if (sides[key(a, b)] == 1) {
      border[a].push_back(b);
      border[b].push_back(a);
    }
  }
  std::vector<Eigen::Triplet<double>> entries;
  for (uint32_t v = 0; v < n; ++v) {
    const std::vector<uint32_t>& ring = border[v].empty() ? all[v] : border[v];
    const bool corner = base.border_corners.empty() ? faces[v] < 2 : base.border_corners[v] != 0;
    if (!border[v].empty() && corner) continue;
    entries.emplace_back(int(v), int(v), 1.0);
    for (uint32_t u : ring) entries.emplace_back(int(v), int(u), -1.0 / double(ring.size()));
  }
  Sparse op(n, n);
  op.setFromTriplets(entries.begin(), entries.end());
  return op;
}

}  // namespace

struct LimitFit::Impl {
  FitWeights settings;
  uint32_t base_vertices = 0;
  SparseRows rows;  // limit positions of the selected level-L vertices, from base points
  Sparse rows_by_column;  // the same by column: rows^T times the targets as one gather per base point
  // Per side, its rows in order along it (ends included), its first curve and how many pieces it has.
  std::vector<std::vector<Eigen::Index>> paths;
  std::vector<uint32_t> path_first_curve, path_pieces;
  std::vector<Eigen::Index> vertex_row;  // row of each drawn base vertex (-1 for the others)
  double ridge = 0;
  Sparse shape;  // the shape term's matrix (empty when no base quad is thin): its pull is shape * initial
  // The normal matrix's other terms, kept to factor it again with reweighted fairness rows.
  Sparse data_normal;  // rows^T rows
  Sparse bilaplacian;
  double fairness_scale = 0;
  Eigen::SimplicialLDLT<Sparse> solver;
  Eigen::VectorXd inverse_diagonal;  // 1 / D of the solver's L D L^T

  // rows^T rows + the fairness term (its scale applied here) + the shape term + the ridge.
  Sparse normal_matrix(const Sparse& fairness) const {
    Sparse normal = data_normal;
    normal += fairness_scale * fairness;
    if (shape.nonZeros() > 0) normal += shape;
    for (Eigen::Index v = 0; v < normal.cols(); ++v) normal.coeffRef(v, v) += ridge;
    return normal;
  }
};

namespace {

// The fit's per-solve kernels, x, y and z in one pass over each sparse matrix where Eigen makes three
// (it walks a sparse matrix once per column of a dense one). Each coordinate gets exactly Eigen's
// operations in Eigen's order, so the results are Eigen's bit for bit (tests/engine/demo.hash holds
// the fitted surface).
using Rows3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

// Each outer slot i of a compressed sparse matrix (a row of a row-major one, a column of a column-major
// one) dotted with the points, in storage order, as Eigen's products sum; done(i, x, y, z) takes it.
template <class Compressed, class Done>
void gather(const Compressed& matrix, const Eigen::MatrixX3d& points, Done&& done) {
  FIRE_ASSERT(matrix.isCompressed(), "the kernels read a compressed sparse matrix's arrays");
  const int* outer = matrix.outerIndexPtr();
  const int* inner = matrix.innerIndexPtr();
  const double* value = matrix.valuePtr();
  const double* px = points.col(0).data();
  const double* py = points.col(1).data();
  const double* pz = points.col(2).data();
  for (Eigen::Index i = 0; i < matrix.outerSize(); ++i) {
    double x = 0, y = 0, z = 0;
    for (int k = outer[i]; k < outer[i + 1]; ++k) {
      const double w = value[k];
      x += w * px[inner[k]];
      y += w * py[inner[k]];
      z += w * pz[inner[k]];
    }
    done(i, x, y, z);
  }
}

// rows * points.
void multiply_rows(const SparseRows& rows, const Eigen::MatrixX3d& points, Eigen::MatrixX3d& out) {
  out.resize(rows.rows(), 3);
  gather(rows, points, [&](Eigen::Index r, double x, double y, double z) { out.row(r) << x, y, z; });
}

// rows^T * targets + anchor (rows^T stored as rows by column), into the solver's permuted order (P b).
void right_hand_side(const Sparse& by_column, const Eigen::SimplicialLDLT<Sparse>& solver,
                     const Eigen::MatrixX3d& targets, const Eigen::MatrixX3d& anchor, Rows3& permuted) {
  const auto& order = solver.permutationP().indices();
  permuted.resize(by_column.cols(), 3);
  gather(by_column, targets, [&](Eigen::Index i, double x, double y, double z) {
    permuted.row(order[i]) << x + anchor(i, 0), y + anchor(i, 1), z + anchor(i, 2);
  });
}

// SimplicialLDLT's solve, from P b (in `permuted`, overwritten) to the solution.
void solve_permuted(const Eigen::SimplicialLDLT<Sparse>& solver, const Eigen::VectorXd& inverse_diagonal,
                    Rows3& permuted, Eigen::MatrixX3d& solution) {
  const Sparse& lower = solver.matrixL().nestedExpression();
  FIRE_ASSERT(lower.isCompressed(), "the kernels read a compressed sparse matrix's arrays");
  const int* outer = lower.outerIndexPtr();
  const int* inner = lower.innerIndexPtr();
  const double* value = lower.valuePtr();
  const Eigen::Index n = lower.cols();
  double* b = permuted.data();
  // L y = P b, column by column (Eigen skips a coordinate that is zero, and so does this).
  for (Eigen::Index i = 0; i < n; ++i) {
    int k = outer[i];
    while (k < outer[i + 1] && inner[k] <= i) ++k;
    const double x = b[3 * i], y = b[3 * i + 1], z = b[3 * i + 2];
    if (x != 0 && y != 0 && z != 0) {
      for (; k < outer[i + 1]; ++k) {
        double* to = b + 3 * inner[k];
        to[0] -= x * value[k];
        to[1] -= y * value[k];
        to[2] -= z * value[k];
      }
    } else {
      for (; k < outer[i + 1]; ++k) {
        double* to = b + 3 * inner[k];
        if (x != 0) to[0] -= x * value[k];
        if (y != 0) to[1] -= y * value[k];
        if (z != 0) to[2] -= z * value[k];
      }
    }
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const double d = inverse_diagonal[i];
    b[3 * i] = d * b[3 * i];
    b[3 * i + 1] = d * b[3 * i + 1];
    b[3 * i + 2] = d * b[3 * i + 2];
  }
  // L^T z = y, row by row of L^T.
  for (Eigen::Index i = n - 1; i >= 0; --i) {
    int k = outer[i];
    while (k < outer[i + 1] && inner[k] <= i) ++k;
    double x = b[3 * i], y = b[3 * i + 1], z = b[3 * i + 2];
    for (; k < outer[i + 1]; ++k) {
      const double* from = b + 3 * inner[k];
      x -= value[k] * from[0];
      y -= value[k] * from[1];
      z -= value[k] * from[2];
    }
    b[3 * i] = x;
    b[3 * i + 1] = y;
    b[3 * i + 2] = z;
  }
  const auto& back = solver.permutationPinv().indices();
  solution.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Index to = back[i];
    solution(to, 0) = b[3 * i];
    solution(to, 1) = b[3 * i + 1];
    solution(to, 2) = b[3 * i + 2];
  }
}

}  // namespace

std::vector<double> shape_weights(const BaseMesh& base, const FitWeights& settings) {
  std::vector<double> weight(base.vertex_count(), 0.0);
  if (!(settings.shape > 0)) return weight;
  for (uint32_t f = 0; f < base.face_count(); ++f) {
    const uint32_t first = base.face_offsets[f];
    if (base.face_offsets[f + 1] - first != 4) continue;
    const double aspect = quad_aspect(base, f);
    if (!(aspect > settings.shape_aspect)) continue;
    const double excess = aspect / settings.shape_aspect - 1;
    for (uint32_t k = 0; k < 4; ++k) {
      double& w = weight[base.face_vertices[first + k]];
      w = std::max(w, std::min(excess * excess, 1.0));
    }
  }
  return weight;
}

LimitFit::LimitFit() = default;
LimitFit::~LimitFit() = default;
LimitFit::LimitFit(LimitFit&&) noexcept = default;
LimitFit& LimitFit::operator=(LimitFit&&) noexcept = default;

Result<LimitFit> LimitFit::build_rows(const catmull_clark::Refinement& refinement,
                                      const catmull_clark::LimitStencils& limit, const BaseMesh& base,
                                      const FitWeights& settings) {
  const uint32_t last = static_cast<uint32_t>(refinement.levels.size() - 1);
  const catmull_clark::Level& level0 = refinement.levels[0];
  const uint32_t nb = base.vertex_count();
  auto impl = std::make_unique<Impl>();
  impl->settings = settings;
  impl->base_vertices = nb;

  std::unordered_map<uint64_t, uint32_t> edge_of_pair;
  for (uint32_t e = 0; e < level0.edge_count(); ++e) {
    const uint32_t a = level0.edge_vertices[2 * e], b = level0.edge_vertices[2 * e + 1];
    edge_of_pair[uint64_t(std::min(a, b)) << 32 | std::max(a, b)] = e;
  }
  // Rows: the drawn base vertices, then the inner level-L vertices of every drawn curve, side by side.
  std::vector<uint32_t> selected;
  impl->vertex_row.assign(nb, -1);
  for (uint32_t v = 0; v < nb; ++v)
    if (base.vertex_drawn[v]) {
      impl->vertex_row[v] = Eigen::Index(selected.size());
      selected.push_back(catmull_clark::last_level_vertex(refinement, v));
    }
  std::vector<uint32_t> chain;
  for (uint32_t s = 0; s < base.side_count(); ++s) {
    const uint32_t first = base.side_curve_offsets[s], end = base.side_curve_offsets[s + 1];
    impl->paths.push_back({impl->vertex_row[base.curve_ends[2 * first]]});
    impl->path_first_curve.push_back(first);
    impl->path_pieces.push_back(end - first);
    for (uint32_t c = first; c < end; ++c) {
      const uint32_t a = base.curve_ends[2 * c], b = base.curve_ends[2 * c + 1];
      auto it = edge_of_pair.find(uint64_t(std::min(a, b)) << 32 | std::max(a, b));
      if (it == edge_of_pair.end())
        return Result<LimitFit>::failure("internal error: curve " + std::to_string(c) + " is not a base edge");
      chain.clear();
      catmull_clark::vertices_along_edge(refinement, 0, it->second, a, chain);
      for (size_t k = 1; k < chain.size(); ++k) {
        impl->paths.back().push_back(Eigen::Index(selected.size()));
        selected.push_back(chain[k]);
      }
      impl->paths.back().push_back(impl->vertex_row[b]);
    }
  }

  catmull_clark::StencilTable table;
  for (uint32_t v : selected) {
    for (uint32_t k = limit.offsets[v]; k < limit.offsets[v + 1]; ++k) {
      table.sources.push_back(limit.sources[k]);
      table.weights.push_back(limit.position[k]);
    }
    table.offsets.push_back(static_cast<uint32_t>(table.sources.size()));
  }
  std::vector<uint8_t> read;  // the rows of the next level's stencils the table reads
  for (uint32_t l = last; l-- > 0;) {
    read.assign(refinement.levels[l + 1].vertex_count, 0);
    for (uint32_t s : table.sources) read[s] = 1;
    table = catmull_clark::compose(table, catmull_clark::stencil_table(refinement, l, read));
  }
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(table.sources.size());
  for (uint32_t r = 0; r < table.row_count(); ++r)
    for (uint32_t k = table.offsets[r]; k < table.offsets[r + 1]; ++k)
      triplets.emplace_back(static_cast<int>(r), static_cast<int>(table.sources[k]), table.weights[k]);
  impl->rows.resize(Eigen::Index(selected.size()), nb);
  impl->rows.setFromTriplets(triplets.begin(), triplets.end());
  LimitFit fit;
  fit.impl_ = std::move(impl);
  return fit;
}

Status LimitFit::factor(const BaseMesh& base, const FitWeights& settings) {
  Impl* impl = impl_.get();
  impl->settings = settings;
  const uint32_t nb = impl->base_vertices;
  impl->data_normal = Sparse(impl->rows.transpose()) * impl->rows;
  const double data_scale = impl->data_normal.diagonal().mean();
  const Sparse laplacian = umbrella(base);
  impl->bilaplacian = laplacian * laplacian;
  const Sparse fairness = Sparse(impl->bilaplacian.transpose()) * impl->bilaplacian;
  impl->fairness_scale = settings.fairness * data_scale / fairness.diagonal().mean();
  // The shape term: the change from the initial base points, measured by the umbrella, costs where base
  // quads are thin. Zero everywhere (no term) when none is.
  const std::vector<double> shape = shape_weights(base, settings);
  if (std::any_of(shape.begin(), shape.end(), [](double w) { return w > 0; })) {
    const Sparse plain = Sparse(laplacian.transpose()) * laplacian;
    const Eigen::Map<const Eigen::VectorXd> per_vertex(shape.data(), Eigen::Index(nb));
    const Sparse weighted = Sparse(laplacian.transpose()) * (per_vertex.asDiagonal() * laplacian);
    impl->shape = (settings.shape * data_scale / plain.diagonal().mean()) * weighted;
  }
  impl->ridge = settings.ridge * data_scale;
  impl->solver.compute(impl->normal_matrix(fairness));
  if (impl->solver.info() != Eigen::Success) return Status::failure("the limit fit's normal matrix could not be factored");
  impl->inverse_diagonal = impl->solver.vectorD().cwiseInverse();
  impl->rows_by_column = impl->rows;
  return Status::success();
}

Result<LimitFit> LimitFit::build(const catmull_clark::Refinement& refinement, const catmull_clark::LimitStencils& limit,
                                 const BaseMesh& base, const FitWeights& settings) {
  Result<LimitFit> fit = build_rows(refinement, limit, base, settings);
  if (!fit) return fit;
  if (Status factored = fit->factor(base, settings); !factored) return Result<LimitFit>::failure(factored.error);
  return fit;
}

namespace {

// A stretch of a network polyline whose two ends are fixed targets, and the rows in between whose
// targets slide along it.
struct Span {
  std::vector<Vec3> line;
  std::vector<double> params;
  std::vector<Eigen::Index> rows;  // in order along the line, ends included
  double length = 0;
};

Span make_span(std::span<const Vec3> line, std::vector<Eigen::Index> rows) {
  Span s{std::vector<Vec3>(line.begin(), line.end()), {}, std::move(rows)};
  s.params = arc_parameters(s.line);
  for (size_t j = 1; j < s.line.size(); ++j) s.length += (s.line[j] - s.line[j - 1]).norm();
  return s;
}

// Re-places the inner targets of a span at the arc-length fractions its fitted limit points have along
// it, reading its polyline as `reading` says; returns the largest move.
double slide(const Span& span, Sampling reading, const Eigen::MatrixX3d& fitted, Eigen::MatrixX3d& targets,
             std::vector<double>& length) {
  const std::vector<Eigen::Index>& rows = span.rows;
  length.assign(rows.size(), 0.0);
  for (size_t k = 1; k < rows.size(); ++k) length[k] = length[k - 1] + (fitted.row(rows[k]) - fitted.row(rows[k - 1])).norm();
  const double total = length.back();
  double largest = 0;
  if (!(total > 0)) return largest;
  for (size_t k = 1; k + 1 < rows.size(); ++k) {
    const Vec3 target = sample_polyline(span.line, span.params, length[k] / total, reading);
    largest = std::max(largest, (target - Vec3(targets.row(rows[k]).transpose())).norm());
    targets.row(rows[k]) = target.transpose();
  }
  return largest;
}

// Splits a whole network edge's span at the polyline samples nearest to its split points' targets, which
// then become those samples exactly; keeps it whole when they would not be distinct, ordered samples.
void snap_split_points(const Span& whole, uint32_t pieces, Eigen::MatrixX3d& targets, std::vector<Span>& out) {
  const size_t steps = (whole.rows.size() - 1) / pieces, last = whole.line.size() - 1;
  std::vector<size_t> at{0};
  for (uint32_t i = 1; i < pieces; ++i) {
    const Vec3 target = targets.row(whole.rows[i * steps]).transpose();
    size_t best = 0;
    for (size_t j = 1; j < last; ++j)
      if ((whole.line[j] - target).squaredNorm() < (whole.line[best] - target).squaredNorm()) best = j;
    if (best <= at.back()) {
      out.push_back(whole);
      return;
    }
    at.push_back(best);
  }
  at.push_back(last);
  for (uint32_t i = 0; i < pieces; ++i) {
    if (i > 0) targets.row(whole.rows[i * steps]) = whole.line[at[i]].transpose();
    std::vector<Eigen::Index> rows(whole.rows.begin() + i * steps, whole.rows.begin() + (i + 1) * steps + 1);
    out.push_back(make_span(std::span<const Vec3>(whole.line).subspan(at[i], at[i + 1] - at[i] + 1), std::move(rows)));
  }
}

// Where along the segment from a to a + d the point nearest to x lies, from 0 to 1 (0 if it has no length).
double segment_fraction(const Vec3& a, const Vec3& d, const Vec3& x) {
  const double squared = d.squaredNorm();
  return squared > 0 ? std::clamp((x - a).dot(d) / squared, 0.0, 1.0) : 0.0;
}

// The arc-length fraction of the point of `span.line` closest to x, searched between fractions lo and hi
// (the neighbouring rows' targets), so that the targets stay in order along the line.
double foot_fraction(const Span& span, const Vec3& x, double lo, double hi) {
  const auto& t = span.params;
  size_t first = size_t(std::upper_bound(t.begin(), t.end(), lo) - t.begin());
  size_t last = size_t(std::lower_bound(t.begin(), t.end(), hi) - t.begin());
  first = first == 0 ? 0 : first - 1;
  last = std::min(last, t.size() - 1);
  double best = std::numeric_limits<double>::infinity(), best_t = 0.5 * (lo + hi);
  for (size_t j = first; j < last; ++j) {
    const Vec3 a = span.line[j], d = span.line[j + 1] - a;
    const double w = segment_fraction(a, d, x);
    const double distance = (a + w * d - x).squaredNorm();
    if (distance < best) {
      best = distance;
      best_t = std::clamp(t[j] + w * (t[j + 1] - t[j]), lo, hi);
    }
  }
  return best_t;
}

// Inner-row fractions are stacked span after span; each span's must increase strictly inside (0, 1).
bool ordered(const std::vector<Span>& spans, const Eigen::VectorXd& fractions) {
  Eigen::Index i = 0;
  for (const Span& span : spans) {
    double previous = 0;
    for (size_t k = 1; k + 1 < span.rows.size(); ++k, ++i) {
      if (!(fractions[i] > previous && fractions[i] < 1)) return false;
      previous = fractions[i];
    }
  }
  return true;
}

// From x to the nearest point of the polyline's segments.
double distance_to_polyline(std::span<const Vec3> line, const Vec3& x) {
  double nearest = std::numeric_limits<double>::infinity();
  for (size_t j = 0; j + 1 < line.size(); ++j) {
    const Vec3 a = line[j], d = line[j + 1] - a;
    nearest = std::min(nearest, (a + segment_fraction(a, d, x) * d - x).squaredNorm());
  }
  return std::sqrt(nearest);
}

// FitWeights::followed_*: per base vertex, the weight of its fairness row, `low` unless it is a source of
// a limit point of a network edge whose fitted points and polyline lie farther than `within` apart
// (either from the other); empty when no vertex gets `low`, or when every edge within `within` lies
// within `close` already.
Eigen::VectorXd followed_weights(const SparseRows& rows, const std::vector<Span>& whole, const Eigen::MatrixX3d& fitted,
                                 double within, double close, double low) {
  std::vector<uint8_t> held(size_t(rows.cols()), 0);
  bool closer = false;  // some followed edge could come closer
  std::vector<Vec3> fitted_line;
  for (const Span& span : whole) {
    // Both ways: the fitted points can lie on the polyline while it bends away between them.
    fitted_line.clear();
    for (Eigen::Index r : span.rows) fitted_line.push_back(fitted.row(r).transpose());
    double farthest = 0;
    for (const Vec3& x : fitted_line) farthest = std::max(farthest, distance_to_polyline(span.line, x));
    for (const Vec3& x : span.line) farthest = std::max(farthest, distance_to_polyline(fitted_line, x));
    if (farthest <= within) {
      closer = closer || farthest > close;
      continue;
    }
    for (Eigen::Index r : span.rows)
      for (SparseRows::InnerIterator it(rows, r); it; ++it) held[size_t(it.col())] = 1;
  }
  if (!closer || std::all_of(held.begin(), held.end(), [](uint8_t h) { return h != 0; })) return {};
  Eigen::VectorXd weights(rows.cols());
  for (Eigen::Index v = 0; v < weights.size(); ++v) weights[v] = held[size_t(v)] ? 1.0 : low;
  return weights;
}

}  // namespace

LimitFit::Report LimitFit::solve(const BaseMesh& base, std::vector<Vec3>& points) const {
  FitRun run(*this, base);
  run.advance(std::numeric_limits<uint32_t>::max());
  points = run.points();
  return run.report();
}

FitRun::FitRun(const LimitFit& fit, const BaseMesh& base) : steps_(fit_steps(*fit.impl_, base)) {}

bool FitRun::advance(uint32_t solves) {
  for (uint32_t k = 0; k < solves && steps_.running(); ++k) steps_.resume();
  return steps_.finished();
}

// LimitFit::solve's body. Each `co_yield Step{}` stands just before a back-substitution, so that one
// resume runs exactly one (and the target updates up to the next); the body starts eagerly (steps.hpp),
// so the setup above the first one runs in FitRun's constructor, the only place `base` is read.
Steps<FitRun::Fitted> FitRun::fit_steps(const LimitFit::Impl& m, const BaseMesh& base) {
  const uint32_t nb = m.base_vertices;
  Eigen::MatrixX3d targets(m.rows.rows(), 3), initial(nb, 3);
  for (uint32_t v = 0; v < nb; ++v) {
    initial.row(v) = base.positions[v].transpose();
    if (m.vertex_row[v] >= 0) targets.row(m.vertex_row[v]) = base.positions[v].transpose();
  }
  // First targets: equal arc-length steps along each piece of each network edge.
  std::vector<Span> whole;  // one per network edge
  std::vector<Vec3> line;
  for (size_t p = 0; p < m.paths.size(); ++p) {
    const std::vector<Eigen::Index>& rows = m.paths[p];
    const uint32_t pieces = m.path_pieces[p];
    const size_t steps = (rows.size() - 1) / pieces;
    line.clear();
    for (uint32_t i = 0; i < pieces; ++i) {
      auto piece = base.curve(m.path_first_curve[p] + i);
      line.insert(line.end(), piece.begin() + (i == 0 ? 0 : 1), piece.end());
      const std::vector<double> t = arc_parameters(piece);
      for (size_t k = 1; k < steps; ++k)
        targets.row(rows[i * steps + k]) = sample_polyline(piece, t, double(k) / double(steps), m.settings.targets).transpose();
    }
    whole.push_back(make_span(line, rows));
  }
  const double size = std::max(bounding_box_diagonal(base.positions), 1e-300);
  const double tolerance = m.settings.tolerance * size;

  LimitFit::Report report;
  Eigen::MatrixX3d solution, fitted;
  Eigen::MatrixX3d anchor = m.ridge * initial;
  if (m.shape.nonZeros() > 0) anchor += m.shape * initial;
  Rows3 permuted;
  // The factorization solves run on: the fit's own, or phase 2's reweighted one (below).
  const Eigen::SimplicialLDLT<Sparse>* solver = &m.solver;
  const Eigen::VectorXd* inverse_diagonal = &m.inverse_diagonal;
  Eigen::SimplicialLDLT<Sparse> reweighted;
  Eigen::VectorXd reweighted_inverse_diagonal;
  auto solve_once = [&] {
    right_hand_side(m.rows_by_column, *solver, targets, anchor, permuted);
    solve_permuted(*solver, *inverse_diagonal, permuted, solution);
    multiply_rows(m.rows, solution, fitted);
    ++report.iterations;
  };
  std::vector<double> scratch;
  co_yield Step{};
  solve_once();
  // Phase 1: the split points slide too, to where the fitted surface puts them along the whole edge.
  for (uint32_t round = 0; round < m.settings.slide_iterations; ++round) {
    double move = 0;
    for (const Span& span : whole) move = std::max(move, slide(span, m.settings.targets, fitted, targets, scratch));
    co_yield Step{};
    solve_once();
    if (move <= tolerance) break;
  }
  // Phase 2: the targets become the foot points of the fitted limit points on the whole edges'
  // polylines (fit.hpp says why); a mixed step that would reorder targets falls back to the plain one.
  Eigen::Index inner = 0;
  for (const Span& span : whole) inner += Eigen::Index(span.rows.size()) - 2;
  Eigen::VectorXd x(inner), g(inner);
  {
    Eigen::Index i = 0;
    for (const Span& span : whole) {
      double previous = 0;
      for (size_t k = 1; k + 1 < span.rows.size(); ++k, ++i)
        previous = x[i] = foot_fraction(span, targets.row(span.rows[k]).transpose(), previous, 1.0);
    }
  }
  auto place = [&](const Eigen::VectorXd& fractions) {
    Eigen::Index i = 0;
    for (const Span& span : whole)
      for (size_t k = 1; k + 1 < span.rows.size(); ++k)
        targets.row(span.rows[k]) = sample_polyline(span.line, span.params, fractions[i++], m.settings.targets).transpose();
  };
  // Each foot is searched between its neighbours' current targets, so that the targets stay in order.
  // Also sums the squared distances of the fitted points to their new feet into `distance`.
  auto feet = [&](const Eigen::VectorXd& current, Eigen::VectorXd& out, double& distance) {
    double largest_move = 0;
    distance = 0;
    Eigen::Index i = 0;
    for (const Span& span : whole) {
      const Eigen::Index count = Eigen::Index(span.rows.size()) - 2;
      for (Eigen::Index k = 0; k < count; ++k, ++i) {
        // At least min_target_spacing of the equal step from the neighbours' targets, so that feet do not
        // gather where the curve bends faster than the surface can follow (fit.hpp).
        const double gap = m.settings.min_target_spacing / double(count + 1);
        double lo = k == 0 ? 0.0 : current[i - 1], hi = k + 1 == count ? 1.0 : current[i + 1];
        if (lo + gap <= hi - gap) {
          lo += gap;
          hi -= gap;
        } else {
          lo = hi = 0.5 * (lo + hi);
        }
        const Vec3 point = fitted.row(span.rows[size_t(k + 1)]).transpose();
        out[i] = foot_fraction(span, point, lo, hi);
        if (m.settings.stall_rounds > 0)
          distance += (sample_polyline(span.line, span.params, out[i], m.settings.targets) - point).squaredNorm();
        largest_move = std::max(largest_move, std::abs(out[i] - current[i]) * span.length);
      }
    }
    return largest_move;
  };
  // Phase 2 runs twice where the first run leaves some curves followed (FitWeights::followed_*): again on
  // the reweighted factorization, from where the first run stopped.
  for (uint32_t rounds = m.settings.feet_iterations;;) {
    // Anderson mixing: next = g - values * gamma, gamma the least-squares solution of steps * gamma = f.
    // It is solved through the steps' Gram matrix, kept up to date a column at a time (a QR of the
    // inner-by-depth steps each round cost more than the back-substitution).
    std::vector<Eigen::VectorXd> step_history, value_history;
    Eigen::MatrixXd gram;
    Eigen::VectorXd previous_g, previous_f;
    std::vector<double> distances;
    for (uint32_t round = 0; round < rounds; ++round) {
      double distance = 0;
      if (feet(x, g, distance) <= tolerance) break;
      distances.push_back(distance);
      const size_t stall = m.settings.stall_rounds;
      if (stall > 0 && distances.size() > stall) {
        const auto window = distances.end() - long(stall);
        const double before = *std::min_element(distances.begin(), window);
        const double lately = *std::min_element(window, distances.end());
        if (before - lately < m.settings.stall_gain * lately) break;
      }
      const Eigen::VectorXd f = g - x;
      if (previous_g.size() > 0) {
        if (step_history.size() == m.settings.anderson_depth) {
          value_history.erase(value_history.begin());
          step_history.erase(step_history.begin());
          const Eigen::Index kept = gram.rows() - 1;
          gram = Eigen::MatrixXd(gram.bottomRightCorner(kept, kept));
        }
        value_history.push_back(g - previous_g);
        step_history.push_back(f - previous_f);
        const Eigen::Index last = Eigen::Index(step_history.size()) - 1;
        gram.conservativeResize(last + 1, last + 1);
        for (Eigen::Index j = 0; j <= last; ++j)
          gram(j, last) = gram(last, j) = step_history[size_t(j)].dot(step_history.back());
      }
      previous_g = g;
      previous_f = f;
      Eigen::VectorXd next = g;
      if (!step_history.empty()) {
        Eigen::VectorXd projected(gram.rows());
        for (Eigen::Index j = 0; j < gram.rows(); ++j) projected[j] = step_history[size_t(j)].dot(f);
        const Eigen::VectorXd gamma = gram.colPivHouseholderQr().solve(projected);
        for (Eigen::Index j = 0; j < gamma.size(); ++j) next -= gamma[j] * value_history[size_t(j)];
      }
      if (!ordered(whole, next)) {
        next = g;
        step_history.clear();
        value_history.clear();
        gram.resize(0, 0);
        previous_g.resize(0);
      }
      x = next;
      place(x);
      co_yield Step{};
      solve_once();
    }
    // The second run has the solves left but phase 3's.
    const uint32_t spent = report.iterations + 1 + m.settings.phase3_iterations;
    const uint32_t left = m.settings.max_iterations - std::min(m.settings.max_iterations, spent);
    if (solver == &reweighted || !(m.settings.followed_fairness < 1) || left == 0) break;
    const Eigen::VectorXd weights =
        followed_weights(m.rows, whole, fitted, m.settings.followed_distance * size, m.settings.close_distance * size,
                         m.settings.followed_fairness);
    if (weights.size() == 0) break;
    reweighted.compute(m.normal_matrix(Sparse(m.bilaplacian.transpose()) * (weights.asDiagonal() * m.bilaplacian)));
    if (reweighted.info() != Eigen::Success) break;  // keeps the first run's result, a fit as good as before
    reweighted_inverse_diagonal = reweighted.vectorD().cwiseInverse();
    solver = &reweighted;
    inverse_diagonal = &reweighted_inverse_diagonal;
    co_yield Step{};
    solve_once();
    rounds = left;
  }
  // The data term the fit minimizes: squared distances of the fitted points to their edges' polylines.
  auto distance_to_curves = [&] {
    double sum = 0;
    for (const Span& span : whole)
      for (size_t k = 1; k + 1 < span.rows.size(); ++k) {
        const Vec3 x = fitted.row(span.rows[k]).transpose();
        sum += (sample_polyline(span.line, span.params, foot_fraction(span, x, 0.0, 1.0), m.settings.targets) - x).squaredNorm();
      }
    return sum;
  };
  const Eigen::MatrixX3d feet_solution = solution, feet_fitted = fitted, feet_targets = targets;
  const double feet_distance = distance_to_curves();
  // Phase 3: the split points settle on polyline samples, and each piece is fitted between them.
  std::vector<Span> split;
  for (size_t p = 0; p < whole.size(); ++p) snap_split_points(whole[p], m.path_pieces[p], targets, split);
  co_yield Step{};
  solve_once();
  while (report.iterations < m.settings.max_iterations) {
    double move = 0;
    for (const Span& span : split) move = std::max(move, slide(span, m.settings.targets, fitted, targets, scratch));
    if (move <= tolerance) break;
    co_yield Step{};
    solve_once();
  }
  if (distance_to_curves() > feet_distance) {
    solution = feet_solution;
    fitted = feet_fitted;
    targets = feet_targets;
  }
  Fitted out;
  out.points.resize(nb);
  for (uint32_t v = 0; v < nb; ++v) out.points[v] = solution.row(v).transpose();
  report.rms = m.rows.rows() ? std::sqrt((fitted - targets).squaredNorm() / double(m.rows.rows())) : 0.0;
  out.report = report;
  co_return out;
}

}  // namespace fire::reconstruct
