// The limit surface as bicubic patches (systems/catmull_clark/bspline_patches.hpp) against the limit itself, from
// limit stencils of a uniform refinement: exact patches equal it at the same (u, v), fitted ones lie within the
// tolerance at points finer than those they were fitted to; regular and irregular counts where they are known.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "platform/obj.hpp"
#include "systems/catmull_clark/bspline_patches.hpp"

namespace {

namespace sd = fire::catmull_clark;
using fire::Vec3;
using fire::kNone;

struct TestCage {
  std::vector<Vec3> points;
  std::vector<uint32_t> offsets{0}, faces, sharp;
  std::vector<uint8_t> corners;
  sd::BaseTopology topology() const {
    return {static_cast<uint32_t>(points.size()), offsets, faces, sharp, corners};
  }
  uint32_t face_count() const { return static_cast<uint32_t>(offsets.size() - 1); }
};

TestCage load(const std::string& name) {
  auto mesh = fire::read_obj(std::string(FIRE_DATA_DIR) + "/meshes/" + name + ".obj");
  INFO(mesh.error());
  REQUIRE(mesh.ok());
  TestCage cage;
  cage.points = mesh->positions;
  cage.offsets = mesh->face_offsets;
  cage.faces = mesh->face_vertices;
  return cage;
}

// n x n quads over [0, n]^2 at height z = 0.3 sin(x) cos(0.7 y), counter-clockwise seen from +z: an open sheet.
TestCage sheet(uint32_t n) {
  TestCage cage;
  for (uint32_t y = 0; y <= n; ++y)
    for (uint32_t x = 0; x <= n; ++x) cage.points.emplace_back(x, y, 0.3 * std::sin(x) * std::cos(0.7 * y));
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      const uint32_t a = y * (n + 1) + x;
      cage.faces.insert(cage.faces.end(), {a, a + 1, a + n + 2, a + n + 1});
      cage.offsets.push_back(static_cast<uint32_t>(cage.faces.size()));
    }
  return cage;
}

// Edges per vertex, and which vertices lie on the border.
struct Valences {
  std::vector<uint32_t> edges;
  std::vector<uint8_t> border;
};
Valences valences(const TestCage& cage) {
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (uint32_t f = 0; f < cage.face_count(); ++f)
    for (uint32_t c = cage.offsets[f]; c < cage.offsets[f + 1]; ++c) {
      const uint32_t a = cage.faces[c], b = cage.faces[c + 1 == cage.offsets[f + 1] ? cage.offsets[f] : c + 1];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  Valences v{std::vector<uint32_t>(cage.points.size(), 0), std::vector<uint8_t>(cage.points.size(), 0)};
  for (const auto& [edge, count] : uses) {
    ++v.edges[edge.first], ++v.edges[edge.second];
    if (count == 1) v.border[edge.first] = v.border[edge.second] = 1;
  }
  return v;
}

// The limit of a cage at the vertices of its level `levels`.
struct Reference {
  sd::Refinement refinement;
  std::vector<Vec3> limit;
  double diagonal = 0;
  int levels = 0;
};
Reference reference(const TestCage& cage, int levels) {
  auto refinement = sd::build_refinement(cage.topology(), {levels, true});
  INFO(refinement.error());
  REQUIRE(refinement.ok());
  Reference ref{std::move(*refinement), {}, 0, levels};
  std::vector<Vec3> last, scratch, normals;
  sd::evaluate(ref.refinement, cage.points, last, scratch);
  auto stencils = sd::build_limit_stencils(ref.refinement);
  REQUIRE(stencils.ok());
  sd::evaluate_limit(*stencils, last, ref.limit, normals);
  ref.diagonal = fire::bounding_box_diagonal(ref.limit);
  return ref;
}

struct Cell {
  int u, v;
};

// The child quad of corner j, as subdivide.hpp numbers it: a quad's children start at its corner j.
std::array<Cell, 4> child_cells(const std::array<Cell, 4>& at, uint32_t j) {
  const Cell c = at[j], n = at[(j + 1) & 3], o = at[(j + 2) & 3], p = at[(j + 3) & 3];
  const std::array<Cell, 4> roles{{c, {(c.u + n.u) / 2, (c.v + n.v) / 2}, {(c.u + o.u) / 2, (c.v + o.v) / 2},
                                   {(c.u + p.u) / 2, (c.v + p.v) / 2}}};
  std::array<Cell, 4> child;
  for (uint32_t role = 0; role < 4; ++role) child[(j + role) & 3] = roles[role];
  return child;
}

// The reference's last-level vertices on patch p, (2^m + 1)^2 of them row by row, m = levels - the patch's level.
std::vector<uint32_t> patch_vertices(const sd::BsplineConversion& c, size_t p, const Reference& ref) {
  const sd::Level& base = ref.refinement.levels[0];
  const uint32_t level = c.patch_level(p);
  uint32_t q = c.patch_face[p];
  for (uint32_t i = 0; i < level; ++i) {
    const uint32_t corner = c.path_corners[c.path_offsets[p] + i];
    q = (i == 0 ? base.face_offsets[q] : 4 * q) + corner;
  }
  const int s = 1 << (ref.levels - int(level)), side = s + 1;
  std::vector<uint32_t> ids(size_t(side) * size_t(side), kNone);
  const sd::Level& last = ref.refinement.last();
  auto descend = [&](auto&& self, uint32_t at_level, uint32_t quad, const std::array<Cell, 4>& at) -> void {
    if (int(at_level) == ref.levels) {
      for (uint32_t t = 0; t < 4; ++t) ids[size_t(at[t].v) * size_t(side) + size_t(at[t].u)] = last.face_vertices[4 * quad + t];
      return;
    }
    const uint32_t first = at_level == 0 ? base.face_offsets[quad] : 4 * quad;
    for (uint32_t j = 0; j < 4; ++j) self(self, at_level + 1, first + j, child_cells(at, j));
  };
  descend(descend, level, q, {{{0, 0}, {s, 0}, {s, s}, {0, s}}});
  return ids;
}

// Largest deviations from the limit, as fractions of its diagonal, over the patches at least `finer` levels
// above the reference's: exact patches at the same (u, v), fitted ones as the distance to the patch.
struct Deviation {
  double exact = 0, fitted = 0;
  size_t exact_checked = 0, fitted_checked = 0, points = 0;
};
Deviation deviation(const sd::BsplineConversion& c, const Reference& ref, int finer) {
  Deviation d;
  for (size_t p = 0; p < c.patches.patch_count(); ++p) {
    if (int(c.patch_level(p)) + finer > ref.levels) continue;
    const std::vector<uint32_t> ids = patch_vertices(c, p, ref);
    const int side = int(std::lround(std::sqrt(double(ids.size()))));
    const bool fitted = c.patches.fitted[p];
    ++(fitted ? d.fitted_checked : d.exact_checked);
    for (int v = 0; v < side; ++v)
      for (int u = 0; u < side; ++u) {
        const Vec3& limit = ref.limit[ids[size_t(v) * size_t(side) + size_t(u)]];
        const double pu = double(u) / (side - 1), pv = double(v) / (side - 1);
        ++d.points;
        if (fitted)
          d.fitted = std::max(d.fitted, sd::distance_to_patch(c.patches, p, limit, pu, pv) / ref.diagonal);
        else
          d.exact = std::max(d.exact, (sd::evaluate_patch(c.patches, p, pu, pv) - limit).norm() / ref.diagonal);
      }
  }
  return d;
}

sd::BsplineConversion convert(const TestCage& cage, const sd::BsplineOptions& options = {}) {
  auto c = sd::bspline_patches(cage.topology(), cage.points, options);
  INFO(c.error());
  REQUIRE(c.ok());
  REQUIRE(c->patches.controls.size() == 16 * c->patches.patch_count());
  REQUIRE(c->exact + c->fitted == c->patches.patch_count());
  return *c;
}

constexpr double kExact = 1e-9;

}  // namespace

TEST_CASE("a torus of regular quads is one exact patch per face", "[bspline]") {
  const TestCage torus = load("torus");
  const sd::BsplineConversion c = convert(torus);
  CHECK(c.exact == torus.face_count());
  CHECK(c.fitted == 0);
  CHECK(c.max_fit_error == 0);
  const Deviation d = deviation(c, reference(torus, 4), 2);
  CHECK(d.exact_checked == torus.face_count());
  CHECK(d.exact < kExact);
}

TEST_CASE("a cube's faces split around its extraordinary corners: exact away from them, fitted at them", "[bspline]") {
  const TestCage cube = load("cube");
  // Two levels: every level-1 quad touches a valence-3 corner; at level 2 three of its four children do not.
  sd::BsplineOptions two_levels;
  two_levels.max_depth = 2;
  const sd::BsplineConversion fixed = convert(cube, two_levels);
  CHECK(fixed.exact == 72);
  CHECK(fixed.fitted == 24);
  CHECK(fixed.fit_level == 2);

  const sd::BsplineConversion c = convert(cube);
  CHECK(c.max_fit_error <= 1e-4);
  CHECK(c.max_fit_error > 0);
  const int fit_level = int(c.fit_level);
  REQUIRE(fit_level >= 2);
  // Checked at twice the resolution the fit saw.
  const Deviation d = deviation(c, reference(cube, fit_level + 5), 5);
  CHECK(d.exact_checked == c.exact);
  CHECK(d.fitted_checked == c.fitted);
  CHECK(d.exact < kExact);
  CHECK(d.fitted <= 1e-4);
  // The conversion's diagonal is the limit's.
  CHECK(std::abs(c.diagonal - reference(cube, 1).diagonal) < 1e-12);
}

TEST_CASE("border faces are exact B-splines with phantom points, corners where the border's rule has them", "[bspline]") {
  TestCage grid = sheet(4);
  const Reference ref = reference(grid, 5);
  // EdgeAndCorner: the four corner vertices (one face) are corners, the other border vertices crease points.
  const sd::BsplineConversion edge_and_corner = convert(grid);
  CHECK(edge_and_corner.exact == 16);
  CHECK(edge_and_corner.fitted == 0);
  CHECK(deviation(edge_and_corner, ref, 2).exact < kExact);

  // The same with FIRE's flags on the four corners.
  grid.corners.assign(grid.points.size(), 0);
  for (uint32_t v : {0u, 4u, 20u, 24u}) grid.corners[v] = 1;
  const sd::BsplineConversion flagged = convert(grid);
  CHECK(flagged.exact == 16);
  CHECK(deviation(flagged, reference(grid, 5), 2).exact < kExact);

  // Unflagged, a one-face vertex is a smooth point of its border: no B-spline patch, so its face is split.
  grid.corners.assign(grid.points.size(), 0);
  sd::BsplineOptions one_level;
  one_level.max_depth = 1;
  const sd::BsplineConversion smooth = convert(grid, one_level);
  CHECK(smooth.exact == 12 + 4 * 3);
  CHECK(smooth.fitted == 4);
  const sd::BsplineConversion deep = convert(grid);
  const Deviation d = deviation(deep, reference(grid, int(deep.fit_level) + 5), 5);
  CHECK(d.exact < kExact);
  CHECK(d.fitted <= 1e-4);
  CHECK(d.fitted_checked == 4);
}

TEST_CASE("faces along infinitely sharp creases are exact on each side", "[bspline]") {
  // A loop of sharp edges around the torus: its vertices are crease vertices with two quads on each side.
  TestCage torus = load("torus");
  const Valences v = valences(torus);
  REQUIRE(std::count(v.edges.begin(), v.edges.end(), 4u) == long(torus.points.size()));
  // The loop through vertex 0 along its first face's first edge, continued straight across each vertex.
  const sd::Level base = std::move(sd::build_refinement(torus.topology(), {0, true})->levels[0]);
  uint32_t from = torus.faces[0], at = torus.faces[1];
  for (uint32_t step = 0; step < torus.points.size(); ++step) {
    torus.sharp.insert(torus.sharp.end(), {from, at});
    uint32_t slot = base.ring_offsets[at];
    while (base.ring_neighbors[slot] != from) ++slot;
    const uint32_t across = base.ring_neighbors[base.ring_offsets[at] + (slot - base.ring_offsets[at] + 2) % 4];
    from = at, at = across;
    if (from == torus.faces[0]) break;
  }
  REQUIRE(torus.sharp.size() >= 8);
  const sd::BsplineConversion c = convert(torus);
  CHECK(c.exact == torus.face_count());
  CHECK(c.fitted == 0);
  CHECK(deviation(c, reference(torus, 4), 2).exact < kExact);

  // Every edge of a cube sharp: its corners are corner vertices with one face between their sharp edges, and
  // every face is a flat square with phantoms on all four sides.
  TestCage cube = load("cube");
  for (uint32_t f = 0; f < cube.face_count(); ++f)
    for (uint32_t k = 0; k < 4; ++k) {
      const uint32_t a = cube.faces[4 * f + k], b = cube.faces[4 * f + (k + 1) % 4];
      if (a < b) cube.sharp.insert(cube.sharp.end(), {a, b});
    }
  const sd::BsplineConversion box = convert(cube);
  CHECK(box.exact == 6);
  CHECK(box.fitted == 0);
  const Reference box_ref = reference(cube, 4);
  CHECK(deviation(box, box_ref, 2).exact < kExact);
  // The phantoms make each patch the bilinear square through its corners: its centre is the face's centre.
  for (size_t p = 0; p < 6; ++p) {
    Vec3 centre = Vec3::Zero();
    for (uint32_t k = 0; k < 4; ++k) centre += 0.25 * cube.points[cube.faces[4 * box.patch_face[p] + k]];
    CHECK((sd::evaluate_patch(box.patches, p, 0.5, 0.5) - centre).norm() < 1e-12);
  }
}

TEST_CASE("the pawn: exact away from its extraordinary vertices, fitted around them and its valence-12 pole",
          "[bspline]") {
  const TestCage pawn = load("pawn");
  const Valences v = valences(pawn);
  REQUIRE(std::count(v.edges.begin(), v.edges.end(), 12u) == 1);
  // Regular: valence 4 inside, 3 on the border. Faces at irregular vertices split once; each of their corners
  // at such a vertex gives one fitted child, the other children are regular.
  uint32_t irregular_faces = 0, irregular_corners = 0;
  for (uint32_t f = 0; f < pawn.face_count(); ++f) {
    uint32_t here = 0;
    for (uint32_t c = pawn.offsets[f]; c < pawn.offsets[f + 1]; ++c)
      here += v.edges[pawn.faces[c]] != (v.border[pawn.faces[c]] ? 3u : 4u);
    irregular_faces += here > 0;
    irregular_corners += here;
  }
  REQUIRE(irregular_faces > 0);
  sd::BsplineOptions one_level;
  one_level.max_depth = 1;
  const sd::BsplineConversion c = convert(pawn, one_level);
  CHECK(c.exact == pawn.face_count() - irregular_faces + 4 * irregular_faces - irregular_corners);
  CHECK(c.fitted == irregular_corners);

  const sd::BsplineConversion fit = convert(pawn);
  CHECK(fit.max_fit_error <= 1e-4);
  const Deviation d = deviation(fit, reference(pawn, int(fit.fit_level) + 3), 3);
  CHECK(d.exact_checked == fit.exact);
  CHECK(d.fitted_checked == fit.fitted);
  CHECK(d.exact < kExact);
  CHECK(d.fitted <= 1e-4);
}

TEST_CASE("the pole of the pawn, fitted from coarse samples, holds the tolerance at finer points", "[bspline]") {
  // The faces within two rings of the valence-12 pole as a cage of their own, so a fine reference is cheap.
  const TestCage pawn = load("pawn");
  const Valences v = valences(pawn);
  const uint32_t pole = uint32_t(std::find(v.edges.begin(), v.edges.end(), 12u) - v.edges.begin());
  std::vector<uint8_t> near(pawn.points.size(), 0);
  near[pole] = 1;
  std::vector<uint8_t> keep(pawn.face_count(), 0);
  for (int ring = 0; ring < 2; ++ring) {
    for (uint32_t f = 0; f < pawn.face_count(); ++f)
      for (uint32_t c = pawn.offsets[f]; c < pawn.offsets[f + 1]; ++c) keep[f] |= near[pawn.faces[c]];
    for (uint32_t f = 0; f < pawn.face_count(); ++f)
      if (keep[f])
        for (uint32_t c = pawn.offsets[f]; c < pawn.offsets[f + 1]; ++c) near[pawn.faces[c]] = 1;
  }
  TestCage cap;
  std::vector<uint32_t> index(pawn.points.size(), kNone);
  for (uint32_t f = 0; f < pawn.face_count(); ++f) {
    if (!keep[f]) continue;
    for (uint32_t c = pawn.offsets[f]; c < pawn.offsets[f + 1]; ++c) {
      uint32_t& i = index[pawn.faces[c]];
      if (i == kNone) {
        i = static_cast<uint32_t>(cap.points.size());
        cap.points.push_back(pawn.points[pawn.faces[c]]);
      }
      cap.faces.push_back(i);
    }
    cap.offsets.push_back(static_cast<uint32_t>(cap.faces.size()));
  }
  REQUIRE(cap.face_count() < 100);
  sd::BsplineOptions coarse;
  coarse.sample_levels = 3;
  const sd::BsplineConversion c = convert(cap, coarse);
  REQUIRE(c.fitted > 0);
  CHECK(c.max_fit_error <= 1e-4);
  // Twice the resolution of its samples.
  const Deviation d = deviation(c, reference(cap, int(c.fit_level) + 4), 4);
  CHECK(d.fitted_checked == c.fitted);
  CHECK(d.exact < kExact);
  CHECK(d.fitted <= 1e-4);
}

TEST_CASE("bad cages and options are refused, naming the problem", "[bspline]") {
  const TestCage fan = load("fan");  // an edge shared by three faces
  auto bad = sd::bspline_patches(fan.topology(), fan.points);
  REQUIRE_FALSE(bad.ok());
  CHECK(bad.error().find("more than 2 faces") != std::string::npos);

  TestCage cube = load("cube");
  cube.points[3].x() = std::nan("");
  auto nan = sd::bspline_patches(cube.topology(), cube.points);
  REQUIRE_FALSE(nan.ok());
  CHECK(nan.error().find("vertex 3") != std::string::npos);

  const TestCage torus = load("torus");
  sd::BsplineOptions options;
  options.tolerance = 0;
  auto zero = sd::bspline_patches(torus.topology(), torus.points, options);
  REQUIRE_FALSE(zero.ok());
  CHECK(zero.error().find("tolerance") != std::string::npos);
  options = {};
  options.max_depth = 0;
  auto shallow = sd::bspline_patches(torus.topology(), torus.points, options);
  REQUIRE_FALSE(shallow.ok());
  CHECK(shallow.error().find("depth") != std::string::npos);
}
