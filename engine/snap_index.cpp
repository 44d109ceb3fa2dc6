#include "engine/snap_index.hpp"

#include <algorithm>
#include <array>
#include <utility>

namespace fire {

namespace {

// Pruning compares squared distances summed in another order than Eigen's norm(); widening the bound by
// far more than that rounding keeps every point that could tie with the best one.
double widen(double squared) { return squared * (1.0 + 1e-9); }

double bound_of(double distance) { return widen(distance * distance); }

// Tree height stays logarithmic (AVL balance on insertion and removal, median splits when built), so a
// fixed stack covers any pool that fits in 32-bit slots.
constexpr size_t kStack = 256;

// The exhaustive searches' order on equal distance: lower edge slot, then lower point index.
bool before(double d, uint32_t e, uint32_t k, const SnapHit& best) {
  if (d != best.distance) return d < best.distance;
  return e != best.edge ? e < best.edge : k < best.point;
}

}  // namespace

std::vector<uint32_t> changed_slots(std::span<const Frame> stamps, Frame seen) {
  std::vector<uint32_t> out;
  for (uint32_t i = 0; i < stamps.size(); ++i)
    if (stamps[i] > seen) out.push_back(i);
  return out;
}

std::vector<uint32_t> changed_slots(std::span<const uint8_t> dirty) {
  std::vector<uint32_t> out;
  for (uint32_t i = 0; i < dirty.size(); ++i)
    if (dirty[i]) out.push_back(i);
  return out;
}

namespace {

void merge_into(double (&lo)[3], double (&hi)[3], const double (&blo)[3], const double (&bhi)[3]) {
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::min(lo[a], blo[a]);
    hi[a] = std::max(hi[a], bhi[a]);
  }
}

double half_area(const double (&lo)[3], const double (&hi)[3]) {
  const double x = hi[0] - lo[0], y = hi[1] - lo[1], z = hi[2] - lo[2];
  return x * y + y * z + z * x;
}

double squared_gap(const double (&lo)[3], const double (&hi)[3], const Vec3& p) {
  double s = 0;
  for (int a = 0; a < 3; ++a) {
    const double g = std::max({lo[a] - p[a], 0.0, p[a] - hi[a]});
    s += g * g;
  }
  return s;
}

}  // namespace

// ---- updates

void SnapIndex::clear() { *this = SnapIndex(); }

bool SnapIndex::same_polyline(uint32_t e, std::span<const Vec3> line) const {
  size_t n = 0;
  for (uint32_t r : edge_leaves_[e]) {
    const Leaf& l = leaves_[r];
    if (l.first != n || l.first + l.count > line.size()) return false;
    for (uint32_t i = 0; i < l.count; ++i) {
      const Vec3& q = line[l.first + i];
      if (q.x() != l.x[i] || q.y() != l.y[i] || q.z() != l.z[i]) return false;
    }
    n += l.count;
  }
  return n == line.size();
}

void SnapIndex::remove_edge(uint32_t e) {
  if (e >= edge_leaves_.size() || edge_leaves_[e].empty()) return;
  for (uint32_t r : edge_leaves_[e]) {
    Leaf& l = leaves_[r];
    remove_leaf(l.node);
    free_node(l.node);
    points_ -= l.count;
    l.edge = kNone;
    free_leaves_.push_back(r);
  }
  edge_leaves_[e].clear();
  --edges_;
}

void SnapIndex::add_leaves(uint32_t e, std::span<const Vec3> line, std::vector<uint32_t>& fresh) {
  if (edge_leaves_.size() <= e) edge_leaves_.resize(e + 1);
  for (uint32_t first = 0; first < line.size(); first += kLeafPoints) {
    uint32_t r;
    if (!free_leaves_.empty()) {
      r = free_leaves_.back();
      free_leaves_.pop_back();
    } else {
      r = static_cast<uint32_t>(leaves_.size());
      leaves_.emplace_back();
    }
    Leaf& l = leaves_[r];
    l.edge = e;
    l.first = first;
    l.count = std::min<uint32_t>(kLeafPoints, static_cast<uint32_t>(line.size()) - first);
    const uint32_t n = new_node();
    Node& node = nodes_[n];
    node.child[0] = kNone;
    node.child[1] = r;
    node.height = 0;
    for (int a = 0; a < 3; ++a) {
      node.box.lo[a] = line[first][a];
      node.box.hi[a] = line[first][a];
    }
    for (uint32_t i = 0; i < l.count; ++i) {
      const Vec3& q = line[first + i];
      l.x[i] = q.x();
      l.y[i] = q.y();
      l.z[i] = q.z();
      for (int a = 0; a < 3; ++a) {
        node.box.lo[a] = std::min(node.box.lo[a], q[a]);
        node.box.hi[a] = std::max(node.box.hi[a], q[a]);
      }
    }
    l.node = n;
    edge_leaves_[e].push_back(r);
    fresh.push_back(n);
    points_ += l.count;
  }
  ++edges_;
}

void SnapIndex::update(const Mesh& mesh, std::span<const uint32_t> changed_edge_slots) {
  for (size_t e = mesh.edge_slots(); e < edge_leaves_.size(); ++e) remove_edge(static_cast<uint32_t>(e));
  if (edge_leaves_.size() > mesh.edge_slots()) edge_leaves_.resize(mesh.edge_slots());
  std::vector<uint32_t> fresh;
  for (uint32_t e : changed_edge_slots) {
    if (!mesh.edge_alive(e)) {
      remove_edge(e);
      continue;
    }
    const auto line = mesh.polyline(e);
    if (e < edge_leaves_.size() && !edge_leaves_[e].empty() && same_polyline(e, line)) continue;
    remove_edge(e);
    add_leaves(e, line, fresh);
  }
  if (fresh.empty()) return;
  const size_t held = leaves_.size() - free_leaves_.size() - fresh.size();
  // Inserting one by one costs a descent each and leaves a looser tree than a top-down build; when most
  // of the index is new (loading, a first sync, an undo that touched everything) build it whole.
  if (fresh.size() > held) {
    rebuild();
    return;
  }
  for (uint32_t n : fresh) insert_leaf(n);
}

void SnapIndex::remap(const CompactionMap& map) {
  std::vector<std::vector<uint32_t>> moved(
      static_cast<size_t>(std::count_if(map.edge.begin(), map.edge.end(), [](uint32_t x) { return x != kNone; })));
  for (uint32_t e = 0; e < edge_leaves_.size(); ++e) {
    if (edge_leaves_[e].empty()) continue;
    const uint32_t to = e < map.edge.size() ? map.edge[e] : kNone;
    if (to == kNone) {
      remove_edge(e);
      continue;
    }
    for (uint32_t r : edge_leaves_[e]) leaves_[r].edge = to;
    moved[to] = std::move(edge_leaves_[e]);
  }
  edge_leaves_ = std::move(moved);
}

// ---- the tree

uint32_t SnapIndex::new_node() {
  if (!free_nodes_.empty()) {
    const uint32_t n = free_nodes_.back();
    free_nodes_.pop_back();
    return n;
  }
  nodes_.emplace_back();
  return static_cast<uint32_t>(nodes_.size() - 1);
}

void SnapIndex::free_node(uint32_t n) { free_nodes_.push_back(n); }

// Picks the sibling that adds the least box area over the path (the surface area heuristic, greedily
// down the tree), pairs the leaf with it under a new node and rebalances on the way up.
void SnapIndex::insert_leaf(uint32_t leaf) {
  nodes_[leaf].parent = kNone;
  if (root_ == kNone) {
    root_ = leaf;
    return;
  }
  const Box lb = nodes_[leaf].box;  // a copy: new_node() below may move the nodes
  uint32_t i = root_;
  while (nodes_[i].child[0] != kNone) {
    const Node& n = nodes_[i];
    Box merged = n.box;
    merge_into(merged.lo, merged.hi, lb.lo, lb.hi);
    const double area = half_area(n.box.lo, n.box.hi), combined = half_area(merged.lo, merged.hi);
    const double here = 2 * combined, inherited = 2 * (combined - area);
    double cost[2];
    for (int s = 0; s < 2; ++s) {
      const Node& c = nodes_[n.child[s]];
      Box b = c.box;
      merge_into(b.lo, b.hi, lb.lo, lb.hi);
      cost[s] = half_area(b.lo, b.hi) + inherited - (c.child[0] != kNone ? half_area(c.box.lo, c.box.hi) : 0.0);
    }
    if (here < cost[0] && here < cost[1]) break;
    i = n.child[cost[0] <= cost[1] ? 0 : 1];
  }
  const uint32_t sibling = i, old_parent = nodes_[sibling].parent;
  const uint32_t p = new_node();
  Node& np = nodes_[p];
  np.parent = old_parent;
  np.child[0] = sibling;
  np.child[1] = leaf;
  np.box = nodes_[sibling].box;
  merge_into(np.box.lo, np.box.hi, lb.lo, lb.hi);
  np.height = nodes_[sibling].height + 1;
  nodes_[sibling].parent = p;
  nodes_[leaf].parent = p;
  if (old_parent == kNone) {
    root_ = p;
  } else {
    Node& op = nodes_[old_parent];
    op.child[op.child[0] == sibling ? 0 : 1] = p;
  }
  refit_up(old_parent);
}

// Takes the leaf out and puts its sibling in its parent's place; the caller frees the leaf node.
void SnapIndex::remove_leaf(uint32_t leaf) {
  if (leaf == root_) {
    root_ = kNone;
    return;
  }
  const uint32_t p = nodes_[leaf].parent, gp = nodes_[p].parent;
  const uint32_t sibling = nodes_[p].child[nodes_[p].child[0] == leaf ? 1 : 0];
  nodes_[sibling].parent = gp;
  if (gp == kNone) {
    root_ = sibling;
  } else {
    Node& g = nodes_[gp];
    g.child[g.child[0] == p ? 0 : 1] = sibling;
  }
  free_node(p);
  refit_up(gp);
}

void SnapIndex::refit_up(uint32_t i) {
  while (i != kNone) {
    i = balance(i);
    Node& n = nodes_[i];
    const Node &a = nodes_[n.child[0]], &b = nodes_[n.child[1]];
    n.height = 1 + std::max(a.height, b.height);
    n.box = a.box;
    merge_into(n.box.lo, n.box.hi, b.box.lo, b.box.hi);
    i = n.parent;
  }
}

// AVL rotation: when one child of `a` is taller by two or more, that child takes a's place, a takes the
// child's shorter grandchild, and the taller grandchild stays. Returns the node now at a's place.
uint32_t SnapIndex::balance(uint32_t a) {
  Node& A = nodes_[a];
  if (A.child[0] == kNone || A.height < 2) return a;
  const int32_t diff = nodes_[A.child[1]].height - nodes_[A.child[0]].height;
  if (diff >= -1 && diff <= 1) return a;
  const int s = diff > 1 ? 1 : 0;
  const uint32_t x = A.child[s];
  Node& X = nodes_[x];
  const uint32_t f = X.child[0], g = X.child[1];
  const bool f_taller = nodes_[f].height > nodes_[g].height;
  const uint32_t tall = f_taller ? f : g, short_ = f_taller ? g : f;

  X.parent = A.parent;
  if (X.parent == kNone) {
    root_ = x;
  } else {
    Node& P = nodes_[X.parent];
    P.child[P.child[0] == a ? 0 : 1] = x;
  }
  X.child[0] = a;
  X.child[1] = tall;
  A.parent = x;
  A.child[s] = short_;
  nodes_[short_].parent = a;

  const Node &a0 = nodes_[A.child[0]], &a1 = nodes_[A.child[1]];
  A.box = a0.box;
  merge_into(A.box.lo, A.box.hi, a1.box.lo, a1.box.hi);
  A.height = 1 + std::max(a0.height, a1.height);
  X.box = A.box;
  merge_into(X.box.lo, X.box.hi, nodes_[tall].box.lo, nodes_[tall].box.hi);
  X.height = 1 + std::max(A.height, nodes_[tall].height);
  return x;
}

void SnapIndex::rebuild() {
  nodes_.clear();
  free_nodes_.clear();
  std::vector<uint32_t> tree_leaves;
  for (uint32_t r = 0; r < leaves_.size(); ++r) {
    Leaf& l = leaves_[r];
    if (l.edge == kNone) continue;
    const uint32_t n = new_node();
    Node& node = nodes_[n];
    node.child[0] = kNone;
    node.child[1] = r;
    node.height = 0;
    for (int a = 0; a < 3; ++a) node.box.lo[a] = node.box.hi[a] = a == 0 ? l.x[0] : a == 1 ? l.y[0] : l.z[0];
    for (uint32_t i = 0; i < l.count; ++i) {
      const double q[3] = {l.x[i], l.y[i], l.z[i]};
      for (int a = 0; a < 3; ++a) {
        node.box.lo[a] = std::min(node.box.lo[a], q[a]);
        node.box.hi[a] = std::max(node.box.hi[a], q[a]);
      }
    }
    l.node = n;
    tree_leaves.push_back(n);
  }
  root_ = tree_leaves.empty() ? kNone : build(tree_leaves, kNone);
}

// Top-down: split at the median of the box centres along the axis where they spread most.
uint32_t SnapIndex::build(std::span<uint32_t> leaves, uint32_t parent) {
  if (leaves.size() == 1) {
    nodes_[leaves[0]].parent = parent;
    return leaves[0];
  }
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::numeric_limits<double>::infinity();
    hi[a] = -lo[a];
  }
  auto centre = [&](uint32_t n, int a) { return nodes_[n].box.lo[a] + nodes_[n].box.hi[a]; };
  for (uint32_t n : leaves)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], centre(n, a));
      hi[a] = std::max(hi[a], centre(n, a));
    }
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
  const size_t mid = leaves.size() / 2;
  std::nth_element(leaves.begin(), leaves.begin() + static_cast<std::ptrdiff_t>(mid), leaves.end(),
                   [&](uint32_t x, uint32_t y) { return centre(x, axis) < centre(y, axis); });
  const uint32_t n = new_node();
  nodes_[n].parent = parent;
  const uint32_t c0 = build(leaves.first(mid), n), c1 = build(leaves.subspan(mid), n);
  Node& node = nodes_[n];
  node.child[0] = c0;
  node.child[1] = c1;
  node.height = 1 + std::max(nodes_[c0].height, nodes_[c1].height);
  node.box = nodes_[c0].box;
  merge_into(node.box.lo, node.box.hi, nodes_[c1].box.lo, nodes_[c1].box.hi);
  return n;
}

// ---- queries

SnapHit SnapIndex::nearest(const Vec3& p, double radius) const {
  SnapHit best;
  if (root_ == kNone) return best;
  double bound = bound_of(radius);
  std::array<std::pair<uint32_t, double>, kStack> stack;
  size_t top = 0;
  stack[top++] = {root_, squared_gap(nodes_[root_].box.lo, nodes_[root_].box.hi, p)};
  while (top > 0) {
    const auto [i, gap] = stack[--top];
    if (gap > bound) continue;
    const Node& n = nodes_[i];
    if (n.child[0] == kNone) {
      const Leaf& l = leaves_[n.child[1]];
      for (uint32_t k = 0; k < l.count; ++k) {
        const double dx = l.x[k] - p.x(), dy = l.y[k] - p.y(), dz = l.z[k] - p.z();
        if (dx * dx + dy * dy + dz * dz > bound) continue;
        const Vec3 q(l.x[k], l.y[k], l.z[k]);
        const double d = (q - p).norm();
        if (d <= radius && before(d, l.edge, l.first + k, best)) {
          best = {l.edge, l.first + k, d};
          bound = bound_of(d);
        }
      }
      continue;
    }
    const double g0 = squared_gap(nodes_[n.child[0]].box.lo, nodes_[n.child[0]].box.hi, p);
    const double g1 = squared_gap(nodes_[n.child[1]].box.lo, nodes_[n.child[1]].box.hi, p);
    // The nearer child goes on top, so it is searched first and tightens the bound for the other.
    const int nearer = g1 < g0 ? 1 : 0;
    const double gn = nearer ? g1 : g0, gf = nearer ? g0 : g1;
    if (gf <= bound) stack[top++] = {n.child[1 - nearer], gf};
    if (gn <= bound) stack[top++] = {n.child[nearer], gn};
  }
  return best;
}

SnapHit SnapIndex::nearest_on_face(const Mesh& mesh, uint32_t f, const Vec3& p, double radius) const {
  SnapHit best;
  double bound = bound_of(radius);
  // The exhaustive search's own order (loop order, then point order) with a strict comparison, so the
  // first of equally near points wins as there; boxes only skip runs that cannot reach the best so far.
  for (uint32_t oe : mesh.face_loop(f)) {
    const uint32_t e = edge_of(oe);
    if (e >= edge_leaves_.size()) continue;
    for (uint32_t r : edge_leaves_[e]) {
      const Leaf& l = leaves_[r];
      if (squared_gap(nodes_[l.node].box.lo, nodes_[l.node].box.hi, p) > bound) continue;
      for (uint32_t k = 0; k < l.count; ++k) {
        const Vec3 q(l.x[k], l.y[k], l.z[k]);
        const double d = (q - p).norm();
        if (d <= radius && d < best.distance) {
          best = {e, l.first + k, d};
          bound = bound_of(d);
        }
      }
    }
  }
  return best;
}

void SnapIndex::nearest_per_edge(const Vec3& p, double radius, std::vector<SnapHit>& out) const {
  out.clear();
  if (root_ == kNone) return;
  const double bound = bound_of(radius);
  std::array<uint32_t, kStack> stack;
  size_t top = 0;
  stack[top++] = root_;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (squared_gap(n.box.lo, n.box.hi, p) > bound) continue;
    if (n.child[0] != kNone) {
      stack[top++] = n.child[0];
      stack[top++] = n.child[1];
      continue;
    }
    const Leaf& l = leaves_[n.child[1]];
    for (uint32_t k = 0; k < l.count; ++k) {
      const Vec3 q(l.x[k], l.y[k], l.z[k]);
      const double d = (q - p).norm();
      if (d <= radius) out.push_back({l.edge, l.first + k, d});
    }
  }
  std::sort(out.begin(), out.end(), [](const SnapHit& a, const SnapHit& b) {
    if (a.edge != b.edge) return a.edge < b.edge;
    return a.distance != b.distance ? a.distance < b.distance : a.point < b.point;
  });
  out.erase(std::unique(out.begin(), out.end(), [](const SnapHit& a, const SnapHit& b) { return a.edge == b.edge; }),
            out.end());
}

// ---- checks

std::string SnapIndex::validate_node(uint32_t i, uint32_t parent, size_t& leaves) const {
  const Node& n = nodes_[i];
  if (n.parent != parent) return "node " + std::to_string(i) + " has a wrong parent";
  if (n.child[0] == kNone) {
    const Leaf& l = leaves_[n.child[1]];
    if (l.node != i || l.edge == kNone) return "tree leaf " + std::to_string(i) + " names a wrong record";
    for (uint32_t k = 0; k < l.count; ++k) {
      const double q[3] = {l.x[k], l.y[k], l.z[k]};
      for (int a = 0; a < 3; ++a)
        if (q[a] < n.box.lo[a] || q[a] > n.box.hi[a]) return "a point lies outside its leaf's box";
    }
    ++leaves;
    return n.height == 0 ? "" : "a tree leaf has a height";
  }
  for (int s = 0; s < 2; ++s) {
    const Node& c = nodes_[n.child[s]];
    for (int a = 0; a < 3; ++a)
      if (c.box.lo[a] < n.box.lo[a] || c.box.hi[a] > n.box.hi[a]) return "a child's box sticks out of its parent's";
    if (auto why = validate_node(n.child[s], i, leaves); !why.empty()) return why;
  }
  const int32_t h0 = nodes_[n.child[0]].height, h1 = nodes_[n.child[1]].height;
  if (n.height != 1 + std::max(h0, h1)) return "node " + std::to_string(i) + " has a wrong height";
  return "";
}

std::string SnapIndex::validate(const Mesh& mesh) const {
  size_t points = 0, edges = 0;
  for (uint32_t e = 0; e < std::max<size_t>(mesh.edge_slots(), edge_leaves_.size()); ++e) {
    const bool held = e < edge_leaves_.size() && !edge_leaves_[e].empty();
    if (held != mesh.edge_alive(e)) return "edge " + std::to_string(e) + (held ? " is held but dead" : " is live but missing");
    if (!held) continue;
    if (!same_polyline(e, mesh.polyline(e))) return "edge " + std::to_string(e) + " holds another polyline";
    for (uint32_t r : edge_leaves_[e])
      if (leaves_[r].edge != e) return "a leaf of edge " + std::to_string(e) + " names another edge";
    points += mesh.edges.point_count[e];
    ++edges;
  }
  if (points != points_ || edges != edges_) return "the point or edge count is off";
  size_t leaves = 0;
  if (root_ != kNone)
    if (auto why = validate_node(root_, kNone, leaves); !why.empty()) return why;
  if (leaves != leaves_.size() - free_leaves_.size()) return "the tree does not hold every leaf record";
  return "";
}

}  // namespace fire
