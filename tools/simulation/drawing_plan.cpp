#include "tools/simulation/drawing_plan.hpp"

#include <algorithm>
#include <numeric>
#include <optional>
#include <set>
#include <string>
#include <tuple>

#include "engine/input_log.hpp"
#include "engine/text.hpp"
#include "systems/sketch/sketch.hpp"

namespace fire::simulation {
using namespace tracking;  // the cameras, calibration and tracking this simulation feeds and checks

std::vector<Vec3> chain_points(const DrawingNetwork& net, const Chain& chain) {
  std::vector<Vec3> out;
  for (const Leg& leg : chain) {
    const std::vector<Vec3>& p = net.curves[leg.curve].points;
    const size_t skip = out.empty() ? 0 : 1;  // the joint is the previous leg's last point
    if (leg.forward)
      out.insert(out.end(), p.begin() + static_cast<std::ptrdiff_t>(skip), p.end());
    else
      out.insert(out.end(), p.rbegin() + static_cast<std::ptrdiff_t>(skip), p.rend());
  }
  return out;
}

bool network_closed(const DrawingNetwork& net) {
  return std::none_of(net.curves.begin(), net.curves.end(), [](const DrawingCurve& c) { return c.border; });
}

namespace {

constexpr uint32_t kNoLoop = ~0u;
constexpr size_t kMaxLegs = 4;
constexpr size_t kMaxLegsStuck = 8;
constexpr size_t kMaxPieces = 4;
constexpr size_t kPieceMargin = 2;  // points
// How far a piece's free end stays from every curve drawn (metres): the sketch's snap distance and a few times
// the tracked pen's error, so the tracked end is not taken for one on the network.
constexpr double kPieceClearance = 0.014;

// Points first..last of a chain, drawn in one pose.
struct Piece {
  int pose;
  size_t first, last;
};

uint32_t chain_start(const DrawingNetwork& net, const Chain& c) {
  const DrawingCurve& k = net.curves[c.front().curve];
  return c.front().forward ? k.a : k.b;
}
uint32_t chain_end(const DrawingNetwork& net, const Chain& c) {
  const DrawingCurve& k = net.curves[c.back().curve];
  return c.back().forward ? k.b : k.a;
}

Chain reversed(const Chain& c) {
  Chain r;
  for (auto it = c.rbegin(); it != c.rend(); ++it) r.push_back({it->curve, !it->forward});
  return r;
}

double chain_length(const DrawingNetwork& net, const Chain& c) {
  double sum = 0;
  for (const Leg& l : c) {
    const auto& p = net.curves[l.curve].points;
    for (size_t i = 1; i < p.size(); ++i) sum += (p[i] - p[i - 1]).norm();
  }
  return sum;
}

struct Sets {
  std::vector<uint32_t> parent;
  explicit Sets(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t find(uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(uint32_t a, uint32_t b) { parent[find(a)] = find(b); }
};

// The network as cells: its faces, then the caps the layout adds. Each curve knows the cells beside it.
struct Cells {
  const DrawingNetwork& net;
  std::vector<std::vector<uint32_t>> at;     // curves at each vertex
  std::vector<std::vector<uint32_t>> curves;  // around each cell
  std::vector<std::vector<uint32_t>> beside;  // cells beside each curve
  std::vector<Chain> caps;                    // cell faces + i is caps[i]
  size_t faces = 0;

  explicit Cells(const DrawingNetwork& n) : net(n), at(n.vertices.size()), beside(n.curves.size()), faces(n.faces.size()) {
    for (uint32_t k = 0; k < net.curves.size(); ++k) {
      at[net.curves[k].a].push_back(k);
      at[net.curves[k].b].push_back(k);
    }
    for (const Chain& f : net.faces) add(f);
  }
  void add(const Chain& loop) {
    const auto c = static_cast<uint32_t>(curves.size());
    curves.emplace_back();
    for (const Leg& l : loop) {
      curves.back().push_back(l.curve);
      beside[l.curve].push_back(c);
    }
  }
  void add_cap(const Chain& loop) {
    caps.push_back(loop);
    add(loop);
  }
  size_t count() const { return curves.size(); }
  uint32_t other(uint32_t k, uint32_t v) const { return net.curves[k].a == v ? net.curves[k].b : net.curves[k].a; }
};

// The cycle through the curves flagged in `in`, from curve `first` walked forward; nullopt where it does not close.
std::optional<Chain> walk_loop(const Cells& g, const std::vector<char>& in, uint32_t first, std::vector<char>& used) {
  const DrawingNetwork& net = g.net;
  Chain cycle{{first, true}};
  used[first] = 1;
  for (;;) {
    const uint32_t v = chain_end(net, cycle);
    if (v == chain_start(net, cycle)) return cycle;
    std::optional<Leg> next;
    for (uint32_t k : g.at[v])
      if (in[k] && !used[k]) next = Leg{k, net.curves[k].a == v};
    if (!next) return std::nullopt;
    used[next->curve] = 1;
    cycle.push_back(*next);
  }
}

// Every cycle through the flagged curves, each from its lowest curve; nullopt unless they are disjoint cycles.
std::optional<std::vector<Chain>> loops_of(const Cells& g, const std::vector<char>& in) {
  std::vector<Chain> loops;
  std::vector<char> used(g.net.curves.size(), 0);
  for (uint32_t k = 0; k < g.net.curves.size(); ++k) {
    if (!in[k] || used[k]) continue;
    std::optional<Chain> loop = walk_loop(g, in, k, used);
    if (!loop) return std::nullopt;
    loops.push_back(std::move(*loop));
  }
  return loops;
}

// Whether the given cells stay connected when only the curves not in `cut` join them.
bool connected(const Cells& g, const std::vector<char>& cell_in, const std::vector<char>& cut) {
  Sets sets(g.count());
  for (uint32_t k = 0; k < g.net.curves.size(); ++k) {
    if (cut[k]) continue;
    const auto& b = g.beside[k];
    for (size_t i = 1; i < b.size(); ++i)
      if (cell_in[b[0]] && cell_in[b[i]]) sets.join(b[0], b[i]);
  }
  std::optional<uint32_t> root;
  for (uint32_t c = 0; c < g.count(); ++c) {
    if (!cell_in[c]) continue;
    if (root && sets.find(c) != *root) return false;
    root = sets.find(c);
  }
  return true;
}

// V - E + F of a set of cells: 1 for a disc, 0 for an annulus.
long euler(const Cells& g, const std::vector<char>& cell_in) {
  std::vector<char> curve(g.net.curves.size(), 0), vertex(g.net.vertices.size(), 0);
  long f = 0;
  for (uint32_t c = 0; c < g.count(); ++c) {
    if (!cell_in[c]) continue;
    ++f;
    for (uint32_t k : g.curves[c]) curve[k] = vertex[g.net.curves[k].a] = vertex[g.net.curves[k].b] = 1;
  }
  return std::count(vertex.begin(), vertex.end(), 1) - std::count(curve.begin(), curve.end(), 1) + f;
}

// The curves that lie beside exactly one of the given cells.
std::vector<char> rim_of(const Cells& g, const std::vector<char>& cell_in) {
  std::vector<char> rim(g.net.curves.size(), 0);
  for (uint32_t k = 0; k < g.net.curves.size(); ++k)
    rim[k] = std::count_if(g.beside[k].begin(), g.beside[k].end(), [&](uint32_t c) { return cell_in[c] != 0; }) == 1;
  return rim;
}

// A handle: a ring of faces whose two rims are non-separating cycles; left out of the first disc, it is drawn
// last, across the hole between its capped rims.
struct Band {
  std::vector<char> cells;
  Chain rim, other_rim;
};

// The shortest cycle of the faces in `inside` that does not cut them apart (of those, the one with fewest curves
// no pose shows whole), and the faces on one side of it as a band. nullopt when there is none. A cycle of two
// curves is passed over: as the first border it would close to a face of two sides, which no surface takes.
std::optional<Band> find_band(const Cells& g, const std::vector<char>& inside, const std::vector<char>& visible) {
  const DrawingNetwork& net = g.net;
  std::vector<char> usable(net.curves.size(), 0);
  for (uint32_t k = 0; k < net.curves.size(); ++k)
    usable[k] = !net.curves[k].border && std::all_of(g.beside[k].begin(), g.beside[k].end(), [&](uint32_t c) { return inside[c] != 0; });
  std::vector<int> left(2 * net.curves.size(), -1);
  for (uint32_t f = 0; f < net.faces.size(); ++f)
    for (const Leg& l : net.faces[f]) left[2 * l.curve + l.forward] = static_cast<int>(f);

  std::set<std::vector<uint32_t>> tried;
  std::vector<std::pair<std::tuple<size_t, size_t, double>, Chain>> cycles;  // (curves, curves no pose shows, length)
  for (uint32_t s = 0; s < net.vertices.size(); ++s) {
    std::vector<uint32_t> parent_curve(net.vertices.size(), kNoLoop);
    std::vector<int> depth(net.vertices.size(), -1);
    std::vector<uint32_t> queue{s};
    depth[s] = 0;
    for (size_t i = 0; i < queue.size(); ++i)
      for (uint32_t k : g.at[queue[i]]) {
        const uint32_t w = g.other(k, queue[i]);
        if (usable[k] && depth[w] < 0) depth[w] = depth[queue[i]] + 1, parent_curve[w] = k, queue.push_back(w);
      }
    for (uint32_t k = 0; k < net.curves.size(); ++k) {
      uint32_t u = net.curves[k].a, w = net.curves[k].b;
      if (!usable[k] || depth[u] < 0 || depth[w] < 0 || parent_curve[u] == k || parent_curve[w] == k) continue;
      std::vector<Leg> down, up;  // lca -> u, then w -> lca
      uint32_t x = u, y = w;
      while (x != y) {
        if (depth[x] >= depth[y]) {
          const uint32_t c = parent_curve[x];
          down.push_back({c, net.curves[c].b == x});
          x = g.other(c, x);
        } else {
          const uint32_t c = parent_curve[y];
          up.push_back({c, net.curves[c].a == y});
          y = g.other(c, y);
        }
      }
      Chain cycle(down.rbegin(), down.rend());
      cycle.push_back({k, true});
      cycle.insert(cycle.end(), up.begin(), up.end());
      if (cycle.size() < 3) continue;
      std::vector<uint32_t> key;
      for (const Leg& l : cycle) key.push_back(l.curve);
      std::sort(key.begin(), key.end());
      const auto hidden = static_cast<size_t>(std::count_if(cycle.begin(), cycle.end(), [&](const Leg& l) { return !visible[l.curve]; }));
      if (tried.insert(key).second) cycles.push_back({{cycle.size(), hidden, chain_length(net, cycle)}, std::move(cycle)});
    }
  }
  std::stable_sort(cycles.begin(), cycles.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  for (const auto& [key, cycle] : cycles) {
    std::vector<char> cut(net.curves.size(), 0);
    for (const Leg& l : cycle) cut[l.curve] = 1;
    if (!connected(g, inside, cut)) continue;
    for (bool side : {true, false}) {
      Band band;
      band.cells.assign(g.count(), 0);
      bool ok = true;
      for (const Leg& l : cycle) {
        const int f = left[2 * l.curve + (l.forward == side)];
        ok = ok && f >= 0 && inside[static_cast<size_t>(f)];
        if (ok) band.cells[static_cast<size_t>(f)] = 1;
      }
      if (!ok || euler(g, band.cells) != 0) continue;
      std::vector<char> rim = rim_of(g, band.cells);
      for (const Leg& l : cycle) ok = ok && rim[l.curve], rim[l.curve] = 0;
      // A far rim of two curves would be capped by a face of two sides: the band goes on across it, ring by
      // ring (along a handle's tube), until its far rim has three curves or more.
      while (ok && std::count(rim.begin(), rim.end(), 1) < 3) {
        bool grew = false;
        for (uint32_t k = 0; k < net.curves.size(); ++k)
          if (rim[k])
            for (uint32_t c : g.beside[k])
              if (!band.cells[c] && inside[c]) band.cells[c] = 1, grew = true;
        ok = grew && euler(g, band.cells) == 0;
        rim = rim_of(g, band.cells);
        for (const Leg& l : cycle) ok = ok && rim[l.curve], rim[l.curve] = 0;
      }
      std::vector<char> used(net.curves.size(), 0);
      const auto first = std::find(rim.begin(), rim.end(), 1);
      if (!ok || first == rim.end()) continue;
      std::optional<Chain> other = walk_loop(g, rim, static_cast<uint32_t>(first - rim.begin()), used);
      if (!other || std::count(rim.begin(), rim.end(), 1) != static_cast<long>(other->size())) continue;
      // The rims share no vertex with each other or with the border: each becomes a loop of its own.
      std::vector<char> on_rim(net.vertices.size(), 0);
      for (const Leg& l : cycle) on_rim[net.curves[l.curve].a] = on_rim[net.curves[l.curve].b] = 1;
      for (uint32_t k = 0; k < net.curves.size(); ++k)
        if (net.curves[k].border) on_rim[net.curves[k].a] = on_rim[net.curves[k].b] = 1;
      if (std::any_of(other->begin(), other->end(), [&](const Leg& l) { return on_rim[net.curves[l.curve].a] || on_rim[net.curves[l.curve].b]; }))
        continue;
      std::vector<char> rest = inside;
      for (uint32_t c = 0; c < g.count(); ++c) rest[c] = rest[c] && !band.cells[c];
      if (!connected(g, rest, std::vector<char>(net.curves.size(), 0))) continue;
      band.rim = cycle;
      band.other_rim = std::move(*other);
      return band;
    }
  }
  return std::nullopt;
}

// The border as strokes, in cycle order: runs between the loop's corners (vertices where only two curves
// meet), each curve a stroke of its own when there are fewer than 3 corners.
std::vector<Chain> border_strokes(const Cells& g, Chain cycle) {
  const DrawingNetwork& net = g.net;
  auto corner = [&](const Leg& leg) { return g.at[leg.forward ? net.curves[leg.curve].a : net.curves[leg.curve].b].size() == 2; };
  const size_t corners = static_cast<size_t>(std::count_if(cycle.begin(), cycle.end(), corner));
  if (corners >= 3) std::rotate(cycle.begin(), std::find_if(cycle.begin(), cycle.end(), corner), cycle.end());
  std::vector<Chain> strokes;
  for (const Leg& leg : cycle) {
    if (strokes.empty() || corners < 3 || corner(leg)) strokes.emplace_back();
    strokes.back().push_back(leg);
  }
  return strokes;
}

// One part of the network: the loop drawn first and the cells its disc covers.
struct Layout {
  Chain first_loop;
  std::vector<char> first_disc;
};

// Which loop of each part is drawn first, which cells its disc covers, and the caps: see drawing_plan.hpp.
// Parts in the order of their lowest face.
Result<std::vector<Layout>> lay_out(Cells& g, const std::vector<char>& visible) {
  using R = Result<std::vector<Layout>>;
  const DrawingNetwork& net = g.net;
  if (net.faces.empty()) return R::failure("the network has no faces");
  Sets parts(g.count());
  for (uint32_t k = 0; k < net.curves.size(); ++k)
    for (size_t i = 1; i < g.beside[k].size(); ++i) parts.join(g.beside[k][0], g.beside[k][i]);
  bool several = false;
  for (uint32_t c = 0; c < g.count(); ++c) several = several || parts.find(c) != parts.find(0);
  std::vector<Layout> out;
  std::vector<std::pair<size_t, Chain>> capped;  // part, loop
  std::vector<char> far(g.count(), 0), done(g.count(), 0);
  for (uint32_t seed = 0; seed < g.count(); ++seed) {
    if (done[parts.find(seed)]) continue;
    done[parts.find(seed)] = 1;
    const std::string which = several ? "part " + std::to_string(out.size() + 1) + " of the network" : "the network";
    std::vector<char> part(g.count(), 0);
    for (uint32_t c = 0; c < g.count(); ++c) part[c] = parts.find(c) == parts.find(seed);
    std::vector<char> border(net.curves.size(), 0);
    for (uint32_t k = 0; k < net.curves.size(); ++k) border[k] = net.curves[k].border && part[g.beside[k][0]];
    std::optional<std::vector<Chain>> loops = loops_of(g, border);
    if (!loops) return R::failure("the border of " + which + " is not closed loops");
    const long twice_genus = 2 - euler(g, part) - static_cast<long>(loops->size());
    if (twice_genus < 0 || twice_genus % 2) return R::failure(which + " is not an orientable surface");

    std::vector<char> inside = part;
    std::vector<Band> bands;
    for (long h = 0; h < twice_genus / 2; ++h) {
      std::optional<Band> band = find_band(g, inside, visible);
      if (!band) return R::failure("no ring of faces around handle " + std::to_string(h + 1) + " of " + which + " could be left for last");
      for (uint32_t c = 0; c < g.count(); ++c)
        if (band->cells[c]) far[c] = 1, inside[c] = 0;
      bands.push_back(std::move(*band));
    }

    Layout layout;
    const size_t index = out.size();
    if (!loops->empty()) {
      // The loop lowest on the object, where it stands: the others are capped.
      auto height = [&](const Chain& loop) {
        double z = 0;
        for (const Leg& l : loop) z += net.vertices[net.curves[l.curve].a].z();
        return z / static_cast<double>(loop.size());
      };
      size_t first = 0;
      for (size_t i = 1; i < loops->size(); ++i)
        if (height((*loops)[i]) < height((*loops)[first])) first = i;
      layout.first_loop = (*loops)[first];
      for (size_t i = 0; i < loops->size(); ++i)
        if (i != first) capped.push_back({index, (*loops)[i]});
      for (const Band& b : bands) capped.push_back({index, b.rim}), capped.push_back({index, b.other_rim});
    } else if (!bands.empty()) {
      layout.first_loop = bands[0].rim;
      capped.push_back({index, bands[0].other_rim});
      for (size_t i = 1; i < bands.size(); ++i) capped.push_back({index, bands[i].rim}), capped.push_back({index, bands[i].other_rim});
    } else {
      // Closed, no handle: the two faces at the top are left for last, across the first loop's hole.
      double best = -std::numeric_limits<double>::infinity();
      std::pair<uint32_t, uint32_t> pair{kNoLoop, kNoLoop};
      auto centre_z = [&](uint32_t f) {
        double z = 0;
        for (const Leg& l : net.faces[f]) z += net.vertices[net.curves[l.curve].a].z();
        return z / static_cast<double>(net.faces[f].size());
      };
      auto shown_around = [&](uint32_t f) {
        return std::all_of(net.faces[f].begin(), net.faces[f].end(), [&](const Leg& l) { return visible[l.curve] != 0; });
      };
      // A border stroke that ends within the sketch's snap distance of where the loop began closes it there: the
      // loop's corners must lie farther apart than that (the rook's crenellations have smaller faces at the top).
      auto corners_apart = [&](uint32_t f, uint32_t h) {
        std::vector<uint32_t> corners;
        for (uint32_t face : {f, h})
          for (const Leg& l : net.faces[face]) corners.push_back(net.curves[l.curve].a), corners.push_back(net.curves[l.curve].b);
        std::sort(corners.begin(), corners.end());
        corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
        for (size_t i = 0; i < corners.size(); ++i)
          for (size_t j = i + 1; j < corners.size(); ++j)
            if ((net.vertices[corners[i]] - net.vertices[corners[j]]).norm() < SketchSettings{}.snap_distance) return false;
        return true;
      };
      for (uint32_t k = 0; k < net.curves.size(); ++k)
        if (g.beside[k].size() == 2 && g.beside[k][0] != g.beside[k][1] && part[g.beside[k][0]]) {
          // Faces whose curves some pose shows first, and whose loop the sketch can close where it is meant to.
          const double z = centre_z(g.beside[k][0]) + centre_z(g.beside[k][1]) +
                           (shown_around(g.beside[k][0]) && shown_around(g.beside[k][1]) ? 1e6 : 0) +
                           (corners_apart(g.beside[k][0], g.beside[k][1]) ? 2e6 : 0);
          if (z > best) best = z, pair = {g.beside[k][0], g.beside[k][1]};
        }
      if (pair.first == kNoLoop) return R::failure(which + " is closed and has no two faces side by side");
      std::vector<char> top(g.count(), 0);
      top[pair.first] = top[pair.second] = far[pair.first] = far[pair.second] = 1;
      std::vector<char> rim = rim_of(g, top), used(net.curves.size(), 0);
      std::optional<Chain> loop = walk_loop(g, rim, static_cast<uint32_t>(std::find(rim.begin(), rim.end(), 1) - rim.begin()), used);
      if (!loop || static_cast<long>(loop->size()) != std::count(rim.begin(), rim.end(), 1))
        return R::failure("the two faces at the top of " + which + " are not bounded by one loop");
      layout.first_loop = std::move(*loop);
    }
    layout.first_disc = part;
    out.push_back(std::move(layout));
  }
  const size_t faces = g.count();
  for (const auto& [index, loop] : capped) g.add_cap(loop);
  for (size_t p = 0; p < out.size(); ++p) {
    std::vector<char>& disc = out[p].first_disc;
    for (uint32_t c = 0; c < faces; ++c) disc[c] = disc[c] && !far[c];
    disc.resize(g.count(), 0);
    for (size_t i = 0; i < capped.size(); ++i) disc[faces + i] = capped[i].first == p;
    // The first loop's disc must be one: its faces and caps a disc whose rim is that loop.
    std::vector<char> rim = rim_of(g, disc), loop(net.curves.size(), 0);
    for (const Leg& l : out[p].first_loop) loop[l.curve] = 1;
    if (euler(g, disc) != 1 || rim != loop)
      return R::failure("the faces and caps inside the first border loop of " +
                        (several ? "part " + std::to_string(p + 1) + " of the network" : std::string("the network")) +
                        " do not make a disc; the simulated person cannot plan it");
  }
  return out;
}

// The drawing as the sketch holds it: which curves are drawn, which cells have surface and which were opened.
struct Drawing {
  const Cells& g;
  std::vector<char> curve, vertex, end_vertex, surface, opened;
  std::vector<std::pair<uint32_t, uint32_t>> bridges;  // the end vertices of each bridge still waiting
  // Derived by update():
  std::vector<uint32_t> face;                  // the sketch face of each surface cell (a cell id)
  std::vector<std::vector<uint32_t>> faces_at;  // the sketch faces each vertex lies on, sorted
  std::vector<uint32_t> loop;                   // the border loop of each vertex (a vertex id) or kNoLoop

  explicit Drawing(const Cells& cells)
      : g(cells), curve(cells.net.curves.size(), 0), vertex(cells.net.vertices.size(), 0), end_vertex(vertex), surface(cells.count(), 0),
        opened(surface) {}

  size_t surface_beside(uint32_t k) const {
    return static_cast<size_t>(std::count_if(g.beside[k].begin(), g.beside[k].end(), [&](uint32_t c) { return surface[c] != 0; }));
  }
  void update() {
    const DrawingNetwork& net = g.net;
    Sets cells(g.count()), loops(net.vertices.size());
    for (uint32_t k = 0; k < net.curves.size(); ++k) {
      const auto& b = g.beside[k];
      if (!curve[k]) {
        // Every cell with surface beside it, also where a cell without (a band's face) comes first: a capped
        // rim's curve lies between a cap, the far side and the band.
        uint32_t first = kNoLoop;
        for (uint32_t c : b) {
          if (!surface[c]) continue;
          if (first == kNoLoop) first = c;
          else cells.join(first, c);
        }
      } else if (surface_beside(k) == 1) {
        loops.join(net.curves[k].a, net.curves[k].b);
      }
    }
    face.assign(g.count(), kNoLoop);
    for (uint32_t c = 0; c < g.count(); ++c)
      if (surface[c]) face[c] = cells.find(c);
    faces_at.assign(net.vertices.size(), {});
    loop.assign(net.vertices.size(), kNoLoop);
    for (uint32_t k = 0; k < net.curves.size(); ++k) {
      if (!curve[k]) continue;
      for (uint32_t v : {net.curves[k].a, net.curves[k].b}) {
        for (uint32_t c : g.beside[k])
          if (surface[c]) faces_at[v].push_back(face[c]);
        if (surface_beside(k) == 1) loop[v] = loops.find(v);
      }
    }
    for (auto& f : faces_at) {
      std::sort(f.begin(), f.end());
      f.erase(std::unique(f.begin(), f.end()), f.end());
    }
  }
  bool inner_curve() const {
    for (uint32_t k = 0; k < g.net.curves.size(); ++k)
      if (curve[k] && surface_beside(k) == 2) return true;
    return false;
  }
  size_t faces_holding(uint32_t a, uint32_t b) const {
    std::vector<uint32_t> both;
    std::set_intersection(faces_at[a].begin(), faces_at[a].end(), faces_at[b].begin(), faces_at[b].end(), std::back_inserter(both));
    return both.size();
  }
  // The cells without surface, not opened, joined to `from` across curves not drawn (and not in `extra`).
  std::vector<uint32_t> far_region(uint32_t from, const std::vector<char>& extra) const {
    std::vector<char> seen(g.count(), 0);
    std::vector<uint32_t> out{from};
    seen[from] = 1;
    for (size_t i = 0; i < out.size(); ++i)
      for (uint32_t k : g.curves[out[i]]) {
        if (curve[k] || extra[k]) continue;
        for (uint32_t c : g.beside[k])
          if (!seen[c] && !surface[c] && !opened[c]) seen[c] = 1, out.push_back(c);
      }
    return out;
  }
  void draw(const Chain& c) {
    for (const Leg& l : c) {
      curve[l.curve] = 1;
      vertex[g.net.curves[l.curve].a] = vertex[g.net.curves[l.curve].b] = 1;
    }
  }
};

}  // namespace

Result<DrawingPlan> plan_drawing(const DrawingNetwork& net, const PoseQuestions& poses, int max_strokes, int undo_after) {
  using R = Result<DrawingPlan>;
  Cells g(net);
  const std::vector<int> every_pose = poses.order(0);
  std::vector<std::vector<char>> shows(every_pose.size(), std::vector<char>(net.curves.size(), 0));
  for (int j : every_pose)
    for (uint32_t k = 0; k < net.curves.size(); ++k) {
      bool all = true;
      for (size_t i = 0; i < net.curves[k].points.size() && all; ++i) all = poses.sees(j, k, i);
      shows[static_cast<size_t>(j)][k] = all;
    }
  auto shown = [&](int pose, const Chain& c) {
    return std::all_of(c.begin(), c.end(), [&](const Leg& l) { return shows[static_cast<size_t>(pose)][l.curve] != 0; });
  };
  std::vector<char> visible(net.curves.size(), 0);
  for (const auto& in_pose : shows)
    for (uint32_t k = 0; k < net.curves.size(); ++k) visible[k] = visible[k] || in_pose[k];
  Result<std::vector<Layout>> parts = lay_out(g, visible);
  if (!parts) return R::failure(parts.error());

  DrawingPlan plan;
  std::vector<PlanStep>& steps = plan.steps;
  Drawing drawing(g);
  // A part's first border loop: the start and direction that need the fewest turns of the object, in runs
  // between corners, or curve by curve where a run is seen whole in no pose.
  auto draw_border = [&](const Layout& part, size_t index) -> Status {
    std::optional<std::pair<size_t, std::vector<int>>> best;  // turns, pose per stroke
    std::vector<Chain> best_strokes, border = border_strokes(g, part.first_loop);
    for (bool single : {false, true}) {
      if (single) {
        if (best) break;
        border.clear();
        for (const Leg& l : part.first_loop) border.push_back({l});
      }
      for (int dir = 0; dir < 2; ++dir)
        for (size_t s = 0; s < border.size(); ++s) {
          std::vector<Chain> strokes;
          for (size_t k = 0; k < border.size(); ++k) {
            const size_t i = dir == 0 ? (s + k) % border.size() : (s + border.size() - k) % border.size();
            strokes.push_back(dir == 0 ? border[i] : reversed(border[i]));
          }
          std::vector<int> pose_of;
          size_t changes = 0;
          for (const Chain& c : strokes) {
            std::optional<int> pick;
            for (int j : poses.order(pose_of.empty() ? (steps.empty() ? 0 : steps.back().pose) : pose_of.back()))
              if (shown(j, c)) {
                pick = j;
                break;
              }
            if (!pick) break;
            if (!pose_of.empty() && *pick != pose_of.back()) ++changes;
            pose_of.push_back(*pick);
          }
          if (pose_of.size() == strokes.size() && (!best || changes < best->first)) {
            best.emplace(changes, pose_of);
            best_strokes = strokes;
          }
        }
    }
    const std::string loop_name = "the first border loop of " +
                                  (parts->size() > 1 ? "part " + std::to_string(index + 1) + " of the network" : std::string("the network"));
    if (!best) return Status::failure("part of " + loop_name + " is seen whole by both cameras in no pose (try another --tilt or --turns)");
    // A stroke a tracked pen cannot draw is taken for a touch, and the border would never be drawn.
    for (const Chain& c : best_strokes)
      if (chain_length(net, c) < kShortestStroke) {
        const Vec3& a = net.vertices[chain_start(net, c)];
        return Status::failure(loop_name + " (through (" + format_double(a.x()) + ", " + format_double(a.y()) + ", " +
                               format_double(a.z()) + "), " + format_mm(chain_length(net, part.first_loop)) +
                               " round) has a stroke " + format_mm(chain_length(net, c)) + " long, under the " +
                               format_mm(kShortestStroke) + " a tracked pen draws");
      }
    for (size_t k = 0; k < best_strokes.size(); ++k) {
      if (steps.empty() || best->second[k] != steps.back().pose) steps.push_back({PlanStep::Kind::Register, best->second[k], {}});
      steps.push_back({PlanStep::Kind::Stroke, best->second[k], chain_points(net, best_strokes[k])});
    }
    plan.border_strokes += static_cast<int>(border.size());
    for (const Chain& c : border) drawing.draw(c);
    for (const Chain& c : border) drawing.end_vertex[chain_start(net, c)] = 1;
    for (uint32_t c = 0; c < g.count(); ++c) drawing.surface[c] = drawing.surface[c] || part.first_disc[c];
    return Status::success();
  };
  auto drawn_so_far = [&] {
    return std::to_string(std::count(drawing.curve.begin(), drawing.curve.end(), 1)) + " of " + std::to_string(net.curves.size()) + " curves drawn";
  };
  size_t next_part = 0;
  if (Status s = draw_border((*parts)[0], 0); !s) return R::failure(s.error);
  ++next_part;
  // Whether a and b lie on one edge of the sketch's mesh (a chain of drawn curves between stroke ends) that
  // the split would start and end on: a point inside it, or its two ends where it bounds `face` (a face of two
  // sides). Else the faces on its two sides hold both ends too, which the sketch tells apart once it can.
  auto same_edge = [&](uint32_t a, uint32_t b, uint32_t face) {
    for (uint32_t first : g.at[a]) {
      if (!drawing.curve[first]) continue;
      uint32_t v = a, k = first;
      bool bounds = false;
      for (;;) {
        for (uint32_t c : g.beside[k]) bounds = bounds || (drawing.surface[c] && drawing.face[c] == face);
        v = g.other(k, v);
        if (v == b) {
          if (!drawing.end_vertex[a] || !drawing.end_vertex[b] || bounds) return true;
          break;
        }
        if (v == a || drawing.end_vertex[v]) break;
        const auto next = std::find_if(g.at[v].begin(), g.at[v].end(), [&](uint32_t x) { return x != k && drawing.curve[x]; });
        if (next == g.at[v].end()) break;
        k = *next;
      }
    }
    return false;
  };
  // What a stroke along chain c does to the far side: nullopt where the sketch would not take it as planned;
  // else the cells that get surface (none for a bridge that waits).
  // Whether the sketch tells apart the faces (and the hole) that hold both ends of a stroke: once the part's
  // first split has shown it which way its faces turn about the outside, it sees from the cameras which one the
  // stroke goes into.
  auto told_apart = [&] { return drawing.inner_curve(); };
  auto across = [&](const Chain& c) -> std::optional<std::vector<uint32_t>> {
    const uint32_t a = chain_start(net, c), b = chain_end(net, c);
    // A face that holds both ends must not take the stroke.
    if (drawing.loop[a] == kNoLoop || drawing.loop[b] == kNoLoop) return std::nullopt;
    if (drawing.faces_holding(a, b) != 0 && !told_apart()) return std::nullopt;
    const std::vector<char> none(net.curves.size(), 0);
    std::vector<char> cut(net.curves.size(), 0);
    for (const Leg& l : c) cut[l.curve] = 1;
    const std::vector<uint32_t> region = drawing.far_region(g.beside[c[0].curve][0], none);
    // The region must be what the sketch takes the hole to be: bounded by the loops of the ends and by bridges.
    for (uint32_t cell : region)
      for (uint32_t k : g.curves[cell])
        if (drawing.curve[k] && drawing.surface_beside(k) == 1 && drawing.loop[net.curves[k].a] != drawing.loop[a] &&
            drawing.loop[net.curves[k].a] != drawing.loop[b])
          return std::nullopt;
    size_t parts = 0;
    std::vector<char> counted(g.count(), 0);
    for (uint32_t cell : region)
      if (!counted[cell]) {
        ++parts;
        for (uint32_t x : drawing.far_region(cell, cut)) counted[x] = 1;
      }
    const bool waiting = std::any_of(drawing.bridges.begin(), drawing.bridges.end(), [&](const auto& br) {
      const uint32_t p = drawing.loop[br.first], q = drawing.loop[br.second];
      return (p == drawing.loop[a] && q == drawing.loop[b]) || (p == drawing.loop[b] && q == drawing.loop[a]);
    });
    if (drawing.loop[a] != drawing.loop[b] && !waiting) {
      if (parts != 1) return std::nullopt;
      return std::vector<uint32_t>{};
    }
    if (parts != 2) return std::nullopt;
    return region;
  };

  // Pieces of a chain, each seen whole in one pose: from the start, the pose that sees farthest along it, and
  // the piece ends at the last point it sees that lies far enough from every curve drawn that the sketch keeps
  // it waiting (its free end off the network); the next piece goes on from there.
  auto in_pieces = [&](const Chain& c, int current, const std::vector<char>& drawn) -> std::optional<std::vector<Piece>> {
    std::vector<std::pair<uint32_t, size_t>> owner;  // curve and point index of each point of the chain
    for (const Leg& l : c) {
      const size_t n = net.curves[l.curve].points.size();
      for (size_t i = owner.empty() ? 0 : 1; i < n; ++i) owner.push_back({l.curve, l.forward ? i : n - 1 - i});
    }
    const std::vector<Vec3> points = chain_points(net, c);
    auto off_network = [&](const Vec3& p) {
      for (uint32_t k = 0; k < net.curves.size(); ++k)
        if (drawn[k])
          for (const Vec3& q : net.curves[k].points)
            if ((p - q).norm() < kPieceClearance) return false;
      return true;
    };
    std::vector<Piece> pieces;
    size_t from = 0;
    while (pieces.size() < kMaxPieces) {
      int best_pose = -1;
      size_t reach = from;
      for (int j : poses.order(current)) {
        if (!poses.sees(j, owner[from].first, owner[from].second)) continue;
        size_t r = from;
        while (r + 1 < points.size() && poses.sees(j, owner[r + 1].first, owner[r + 1].second)) ++r;
        if (r > reach) reach = r, best_pose = j;
      }
      if (best_pose < 0) return std::nullopt;
      if (reach + 1 == points.size()) {
        pieces.push_back({best_pose, from, reach});
        return pieces;
      }
      // A few points short of the last one seen, where the pen rests lit and both cameras still see it; closer
      // to it where only that lets another pose go on from the free end.
      auto cut_at = [&](size_t margin) {
        size_t cut = reach > from + margin ? reach - margin : from;
        while (cut > from && !off_network(points[cut])) --cut;
        return cut;
      };
      auto goes_on = [&](size_t cut) {  // some pose sees on from the free end, past the last point this one sees
        for (int j : poses.order(best_pose)) {
          bool all = true;
          for (size_t i = cut; i <= reach + 1 && all; ++i) all = poses.sees(j, owner[i].first, owner[i].second);
          if (all) return true;
        }
        return false;
      };
      size_t cut = cut_at(kPieceMargin);
      for (size_t margin = kPieceMargin; margin-- > 0 && !goes_on(cut);)
        if (goes_on(cut_at(margin))) cut = cut_at(margin);
      if (cut <= from + 2) return std::nullopt;
      pieces.push_back({best_pose, from, cut});
      from = cut;
      current = best_pose;
    }
    return std::nullopt;
  };

  // The curves along a crease of the object are marked sharp as soon as they are drawn with faces on both sides (the
  // border is a crease already), so that the surface shown while the drawing grows keeps its creases. The sketch
  // holds a run of curves through vertices where only two meet and no stroke ended as one curve, which one touch
  // marks and a second would unmark (cmd sharp toggles): each run is touched once, in the middle of its longest
  // curve, when all its curves are to be marked, and at the end of the drawing when any is.
  std::vector<char> marked(net.curves.size(), 0);
  const bool creased = std::any_of(net.curves.begin(), net.curves.end(), [](const auto& c) { return c.sharp; });
  std::vector<double> length(net.curves.size(), 0);
  if (creased)
    for (uint32_t k = 0; k < net.curves.size(); ++k) length[k] = chain_length(net, {{k, true}});
  auto mark_creases = [&](bool at_end) {
    if (!creased) return;
    auto to_mark = [&](uint32_t k) { return net.curves[k].sharp && drawing.curve[k] && drawing.surface_beside(k) == 2; };
    Sets runs(net.curves.size());
    for (uint32_t v = 0; v < net.vertices.size(); ++v) {
      if (drawing.end_vertex[v]) continue;
      std::vector<uint32_t> drawn_here;
      for (uint32_t k : g.at[v])
        if (drawing.curve[k]) drawn_here.push_back(k);
      if (drawn_here.size() == 2) runs.join(drawn_here[0], drawn_here[1]);
    }
    std::vector<char> any(net.curves.size(), 0), all(net.curves.size(), 1), done(net.curves.size(), 0);
    std::vector<uint32_t> longest(net.curves.size(), kNoLoop), run_of(net.curves.size(), kNoLoop);
    for (uint32_t k = 0; k < net.curves.size(); ++k) {
      if (!drawing.curve[k]) continue;
      const uint32_t run = run_of[k] = runs.find(k);
      any[run] |= to_mark(k);
      all[run] &= to_mark(k);
      done[run] |= marked[k];
      if (longest[run] == kNoLoop || length[k] > length[longest[run]]) longest[run] = k;
    }
    std::vector<char> touch(net.curves.size(), 0);
    for (uint32_t run = 0; run < net.curves.size(); ++run) {
      if (longest[run] == kNoLoop || done[run] || !(at_end ? any[run] : all[run])) continue;
      touch[run] = 1;
      const std::vector<Vec3>& points = net.curves[longest[run]].points;
      steps.push_back({PlanStep::Kind::Sharp, steps.back().pose, {points[points.size() / 2]}});
      ++plan.sharp;
    }
    for (uint32_t k = 0; k < net.curves.size(); ++k)
      if (run_of[k] != kNoLoop && touch[run_of[k]]) marked[k] = 1;
  };

  int pose = steps.back().pose, splits = 0;
  for (;;) {
    drawing.update();
    mark_creases(false);
    // A cap that has become a face of its own, apart from the border, is opened: the pen touches it, cmd hole.
    bool opened = false;
    for (uint32_t cap = static_cast<uint32_t>(g.faces); cap < g.count() && !opened; ++cap) {
      if (!drawing.surface[cap]) continue;
      const uint32_t f = drawing.face[cap];
      bool alone = true;
      for (uint32_t c = 0; c < g.count(); ++c) alone = alone && (c == cap || drawing.face[c] != f);
      for (uint32_t k : g.curves[cap]) {
        alone = alone && drawing.curve[k] && drawing.surface_beside(k) == 2;
        for (uint32_t v : {net.curves[k].a, net.curves[k].b}) alone = alone && drawing.loop[v] == kNoLoop;
      }
      if (!alone) continue;
      const std::vector<Vec3> rim = chain_points(net, g.caps[cap - g.faces]);
      Vec3 centre = Vec3::Zero();
      for (const Vec3& p : rim) centre += p;
      steps.push_back({PlanStep::Kind::Hole, pose, {centre / static_cast<double>(rim.size())}});
      drawing.surface[cap] = 0;
      drawing.opened[cap] = 1;
      ++plan.holes;
      opened = true;
    }
    if (opened) continue;

    // Chains of curves not drawn between points drawn: (legs * 1e6 + length: fewest legs, then shortest).
    auto chains = [&](size_t max_legs) {
    std::vector<std::pair<double, Chain>> candidates;
    for (uint32_t a = 0; a < net.vertices.size(); ++a) {
      if (!drawing.vertex[a]) continue;
      std::vector<Chain> stack{{}};
      while (!stack.empty()) {
        Chain c = std::move(stack.back());
        stack.pop_back();
        const uint32_t v = c.empty() ? a : chain_end(net, c);
        for (uint32_t k : g.at[v]) {
          if (drawing.curve[k] || std::any_of(c.begin(), c.end(), [&](const Leg& l) { return l.curve == k; })) continue;
          Chain next = c;
          next.push_back({k, net.curves[k].a == v});
          const uint32_t w = chain_end(net, next);
          if (drawing.vertex[w]) {
            const double length = chain_length(net, next);
            if (w != a && length >= kShortestStroke) candidates.emplace_back(double(next.size()) * 1e6 + length, std::move(next));
          } else if (next.size() < max_legs) {
            stack.push_back(std::move(next));
          }
        }
      }
    }
    std::stable_sort(candidates.begin(), candidates.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    return candidates;
    };
    struct Pick {
      Chain chain;
      std::vector<Piece> pieces;  // one, unless the chain is drawn in pieces
      std::vector<uint32_t> surfaced;
      bool bridge;  // waits for a second one between the same two loops
    };
    // Whether the sketch would take chain c as planned, and what it does to the far side.
    auto takes = [&](const Chain& c) -> std::optional<std::pair<std::vector<uint32_t>, bool>> {
      const uint32_t a = chain_start(net, c), b = chain_end(net, c);
      // The cell the chain starts in: one with surface where it has any (a capped rim's curve lies between the
      // cap, a face of the disc, and the far side).
      const std::vector<uint32_t>& beside = g.beside[c[0].curve];
      const auto in_face = std::find_if(beside.begin(), beside.end(), [&](uint32_t cell) { return drawing.surface[cell] != 0; });
      if (in_face != beside.end()) {
        // Of several faces that hold both ends, the sketch takes the one the stroke goes into where it tells
        // them apart; else the nearest, which may be the wrong one.
        if (drawing.faces_holding(a, b) == 0 || same_edge(a, b, drawing.face[*in_face]) ||
            (drawing.faces_holding(a, b) > 1 && !told_apart()))
          return std::nullopt;
        return std::pair{std::vector<uint32_t>{}, false};
      }
      std::optional<std::vector<uint32_t>> surfaced = across(c);
      if (!surfaced) return std::nullopt;
      return std::pair{*surfaced, surfaced->empty()};
    };
    auto choose = [&](const std::vector<std::pair<double, Chain>>& candidates) {
    std::optional<Pick> pick;
    for (int j : poses.order(pose)) {
      for (const auto& [key, c] : candidates) {
        if (!shown(j, c)) continue;
        const auto took = takes(c);
        if (!took) continue;
        const std::vector<Vec3> points = chain_points(net, c);
        pick.emplace(Pick{c, {{j, 0, points.size() - 1}}, took->first, took->second});
        break;
      }
      if (pick) break;
    }
    // A chain no pose shows whole is drawn in pieces, the object turned between them.
    for (size_t i = 0; i < candidates.size() && !pick; ++i) {
      const Chain& c = candidates[i].second;
      const auto took = takes(c);
      if (!took) continue;
      std::optional<std::vector<Piece>> pieces = in_pieces(c, pose, drawing.curve);
      if (pieces) pick.emplace(Pick{c, std::move(*pieces), took->first, took->second});
    }
    return pick;
    };
    // Longer chains only where the short ones all end on one curve drawn, or cannot be seen.
    std::vector<std::pair<double, Chain>> candidates = chains(kMaxLegs);
    std::optional<Pick> pick = choose(candidates);
    if (!pick) {
      candidates = chains(kMaxLegsStuck);
      pick = choose(candidates);
    }
    const auto strokes = std::count_if(steps.begin(), steps.end(), [](const PlanStep& s) { return s.kind == PlanStep::Kind::Stroke; });
    if (max_strokes > 0 && strokes >= max_strokes) break;
    if (!pick && next_part < parts->size()) {
      // This part is done as far as it can be: the next one starts with its border, apart from the rest.
      if (Status s = draw_border((*parts)[next_part], next_part); !s) return R::failure(s.error + "; " + drawn_so_far());
      ++next_part;
      pose = steps.back().pose;
      continue;
    }
    if (!pick) {
      // Nothing left it can draw: done when every curve is drawn, else it says which curve stopped it and why.
      const auto first = std::find(drawing.curve.begin(), drawing.curve.end(), 0);
      if (first == drawing.curve.end()) {
        for (uint32_t cap = static_cast<uint32_t>(g.faces); cap < g.count(); ++cap)
          if (!drawing.opened[cap])
            return R::failure("the simulated person cannot open the hole inside the loop through (" +
                              format_double(net.vertices[net.curves[g.caps[cap - g.faces][0].curve].a].x()) + ", " +
                              format_double(net.vertices[net.curves[g.caps[cap - g.faces][0].curve].a].y()) + ", " +
                              format_double(net.vertices[net.curves[g.caps[cap - g.faces][0].curve].a].z()) +
                              "): it touches the border");
        break;
      }
      const auto k = static_cast<uint32_t>(first - drawing.curve.begin());
      auto reaches = [&](const Chain& c) { return std::any_of(c.begin(), c.end(), [&](const Leg& l) { return l.curve == k; }); };
      bool reached = false, seen_whole = false;
      for (const auto& [key, c] : candidates) {
        if (!reaches(c)) continue;
        reached = true;
        for (int j : poses.order(0)) seen_whole = seen_whole || shown(j, c);
      }
      const std::string why =
          chain_length(net, {{k, true}}) < kShortestStroke && !reached
              ? "it is " + format_double(1000 * chain_length(net, {{k, true}})) + " mm long, and no stroke of up to " +
                    std::to_string(kMaxLegsStuck) + " curves through it is " + format_double(1000 * kShortestStroke) +
                    " mm long, the shortest a tracked pen draws"
          : !reached ? "no stroke of up to " + std::to_string(kMaxLegsStuck) + " curves from what is drawn reaches it"
          : !seen_whole ? "both cameras see no stroke that would draw it whole in any pose (try another --tilt or --turns)"
                        : "every stroke that would draw it is one the sketch would take otherwise (between two points of one curve "
                          "drawn, or on a face it was not meant for)";
      const Vec3& a = net.vertices[net.curves[k].a];
      return R::failure("the simulated person cannot draw curve " + std::to_string(k) + " (from (" + format_double(a.x()) + ", " +
                        format_double(a.y()) + ", " + format_double(a.z()) + ")): " + why + "; " + drawn_so_far());
    }
    const std::vector<Vec3> points = chain_points(net, pick->chain);
    for (const Piece& piece : pick->pieces) {
      if (piece.pose != pose) steps.push_back({PlanStep::Kind::Register, piece.pose, {}});
      pose = piece.pose;
      steps.push_back({PlanStep::Kind::Stroke, pose, {points.begin() + static_cast<std::ptrdiff_t>(piece.first), points.begin() + static_cast<std::ptrdiff_t>(piece.last) + 1}});
    }
    plan.pieces += static_cast<int>(pick->pieces.size()) - 1;
    const uint32_t from = drawing.loop[chain_start(net, pick->chain)], to = drawing.loop[chain_end(net, pick->chain)];
    if (pick->bridge) {
      drawing.bridges.push_back({chain_start(net, pick->chain), chain_end(net, pick->chain)});
    } else if (from != to && !pick->surfaced.empty()) {
      // The wall between the two loops has surface now: the bridge that waited there is part of it.
      std::erase_if(drawing.bridges, [&](const auto& br) {
        const uint32_t p = drawing.loop[br.first], q = drawing.loop[br.second];
        return (p == from && q == to) || (p == to && q == from);
      });
    }
    drawing.draw(pick->chain);
    for (uint32_t c : pick->surfaced) drawing.surface[c] = 1;
    drawing.end_vertex[chain_start(net, pick->chain)] = drawing.end_vertex[chain_end(net, pick->chain)] = 1;
    if (++splits == undo_after) {
      PlanStep again = steps.back();
      steps.push_back({PlanStep::Kind::Undo, pose, {}});
      steps.push_back(std::move(again));
    }
  }
  drawing.update();
  mark_creases(true);
  plan.curves_drawn = static_cast<size_t>(std::count(drawing.curve.begin(), drawing.curve.end(), 1));
  return plan;
}

}  // namespace fire::simulation
