#include "engine/snap_index.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <utility>

namespace fire {

namespace {

// Pruning compares squared distances summed in another order than Eigen's norm(); widening the bound by
// far more than that rounding keeps every point that could tie with the best one.
double widen(double squared) { return squared * (1.0 + 1e-9); }

double bound_of(double distance) { return widen(distance * distance); }

// Tree height stays logarithmic (depth_limit below), so a fixed stack covers any pool that fits in
// 32-bit slots.
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


namespace {

float round_down(double x) {
  const float f = static_cast<float>(x);
  return double(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}

float round_up(double x) {
  const float f = static_cast<float>(x);
  return double(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

template <class B>
void merge_into(B& into, const B& b) {
  for (int a = 0; a < 3; ++a) {
    into.lo[a] = std::min(into.lo[a], b.lo[a]);
    into.hi[a] = std::max(into.hi[a], b.hi[a]);
  }
}

template <class B>
double half_area(const B& b) {
  const double x = double(b.hi[0]) - b.lo[0], y = double(b.hi[1]) - b.lo[1], z = double(b.hi[2]) - b.lo[2];
  return x * y + y * z + z * x;
}

template <class B>
double squared_gap(const B& b, const Vec3& p) {
  double s = 0;
  for (int a = 0; a < 3; ++a) {
    const double g = std::max(std::max(double(b.lo[a]) - p[a], p[a] - double(b.hi[a])), 0.0);
    s += g * g;
  }
  return s;
}

using DoublePair = double __attribute__((vector_size(16)));
using FloatPair = float __attribute__((vector_size(8)));
using FloatQuad = float __attribute__((vector_size(16)));

// squared_gap() of a node's entries 2h and 2h+1 at once, with the same arithmetic in the same order; NaN
// for an empty entry, which no bound admits. (Pairs, not one four-wide vector: without AVX, GCC spills
// four-wide doubles through memory.)
template <class Node>
DoublePair entry_gaps(const Node& n, int h, const Vec3& p) {
  DoublePair s = {0, 0};
  for (int a = 0; a < 3; ++a) {
    FloatPair lo, hi;
    std::memcpy(&lo, n.lo[a] + 2 * h, sizeof lo);
    std::memcpy(&hi, n.hi[a] + 2 * h, sizeof hi);
    const DoublePair below = __builtin_convertvector(lo, DoublePair) - p[a];
    const DoublePair above = p[a] - __builtin_convertvector(hi, DoublePair);
    DoublePair g = below < above ? above : below;
    g = g < 0.0 ? 0.0 : g;
    s += g * g;
  }
  return s;
}

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Doubles a full pool's capacity and writes to all of it at once, so that the memory's first-touch page
// faults fall on this rare step instead of on later insertions one by one (removed leaf records are not
// reused until purged, so insertions keep reaching fresh memory).
template <class T>
void grow(std::vector<T>& v) {
  if (v.size() < v.capacity()) return;
  const size_t n = v.size();
  v.reserve(std::max<size_t>(64, 2 * n));
  v.resize(v.capacity());
  v.resize(n);
}

// The depth a subtree with this many leaves may reach before it is rebuilt.
int32_t depth_limit(uint32_t leaves) { return 2 * int32_t(std::bit_width(leaves)) + 2; }

}  // namespace

// Entry 4s is never empty, and an empty entry's NaN loses every comparison, so it drops out of the union.
inline SnapIndex::Box SnapIndex::Node::box(int s) const {
  Box b = entry_box(4 * s);
  for (int k = 4 * s + 1; k < 4 * s + 4; ++k)
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = lo[a][k] < b.lo[a] ? lo[a][k] : b.lo[a];
      b.hi[a] = hi[a][k] > b.hi[a] ? hi[a][k] : b.hi[a];
    }
  return b;
}

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

// The edge's leaf records stay in the tree, dead: NaN points, which no query admits (as nanoflann's
// dynamic index marks its removed points), until purge_dead() takes them out together.
void SnapIndex::remove_edge(uint32_t e) {
  if (e >= edge_leaves_.size() || edge_leaves_[e].empty()) return;
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  for (uint32_t r : edge_leaves_[e]) {
    Leaf& l = leaves_[r];
    points_ -= l.count;
    l.edge = kNone;
    std::fill_n(l.x, kLeafPoints, nan);
    std::fill_n(l.y, kLeafPoints, nan);
    std::fill_n(l.z, kLeafPoints, nan);
    dead_leaves_.push_back(r);
  }
  edge_leaves_[e].clear();
  --edges_;
}

// Dead leaf records cost queries only the visits their boxes still draw; once they are more than an
// eighth of the live ones, one refit for all of them (after the caller's refit_touched()) is cheap per
// record.
void SnapIndex::purge_dead() {
  const size_t live = leaves_.size() - free_leaves_.size() - dead_leaves_.size();
  if (dead_leaves_.size() * 8 <= live) return;
  for (uint32_t r : dead_leaves_) {
    remove_leaf(r | kLeafRef);
    free_leaves_.push_back(r);
  }
  dead_leaves_.clear();
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
      grow(leaves_);
      leaves_.emplace_back();
    }
    Leaf& l = leaves_[r];
    l.edge = e;
    l.first = first;
    l.count = std::min<uint32_t>(kLeafPoints, static_cast<uint32_t>(line.size()) - first);
    l.parent = kNone;
    double lo[3], hi[3];
    for (int a = 0; a < 3; ++a) lo[a] = hi[a] = line[first][a];
    for (uint32_t i = 0; i < l.count; ++i) {
      const Vec3& q = line[first + i];
      l.x[i] = q.x();
      l.y[i] = q.y();
      l.z[i] = q.z();
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], q[a]);
        hi[a] = std::max(hi[a], q[a]);
      }
    }
    for (int a = 0; a < 3; ++a) {
      l.box.lo[a] = round_down(lo[a]);
      l.box.hi[a] = round_up(hi[a]);
    }
    // Unused places are infinitely far, so queries test points in pairs without a bounds check.
    for (uint32_t i = l.count; i < kLeafPoints; ++i) l.x[i] = l.y[i] = l.z[i] = std::numeric_limits<double>::infinity();
    edge_leaves_[e].push_back(r);
    fresh.push_back(r);
    points_ += l.count;
  }
  ++edges_;
}

void SnapIndex::update(const Mesh& mesh, std::span<const uint32_t> changed_edge_slots) {
  for (size_t e = mesh.edge_slots(); e < edge_leaves_.size(); ++e) remove_edge(static_cast<uint32_t>(e));
  if (edge_leaves_.size() > mesh.edge_slots()) edge_leaves_.resize(mesh.edge_slots());
  std::vector<uint32_t> fresh;
  for (uint32_t slot : changed_edge_slots) {
    const EdgeIndex e{slot};
    if (!mesh.edge_alive(e)) {
      remove_edge(e);
      continue;
    }
    const auto line = mesh.polyline(e);
    if (e < edge_leaves_.size() && !edge_leaves_[e].empty() && same_polyline(e, line)) continue;
    remove_edge(e);
    add_leaves(e, line, fresh);
  }
  purge_dead();
  const size_t held = leaves_.size() - free_leaves_.size() - dead_leaves_.size() - fresh.size();
  // Inserting one by one costs a descent each and leaves a looser tree than a top-down build; when most
  // of the index is new (loading, a first sync, an undo that touched everything) build it whole.
  if (!fresh.empty() && fresh.size() > held) {
    rebuild();
  } else {
    // Removals refit once for all; each insertion refits (and rebalances) before the next descends, or
    // a curve's leaves would pile up in one deep chain.
    refit_touched();
    for (uint32_t r : fresh) insert_leaf(r | kLeafRef);
  }
  root_box_ = root_ == kNone ? Box{} : box_of(root_);
}

void SnapIndex::sync(const Mesh& mesh) {
  const uint64_t compactions = mesh.last_compaction().count;
  if (synced_ && compactions == synced_compactions_ + 1) {
    // Compaction keeps each survivor's stamp, so after relabelling only real changes are re-read.
    remap(mesh.last_compaction().map);
  } else if (!synced_ || compactions != synced_compactions_) {
    clear();
    std::vector<uint32_t> all(mesh.edge_slots());
    for (uint32_t e = 0; e < all.size(); ++e) all[e] = e;
    update(mesh, all);
    synced_ = true;
    synced_frame_ = mesh.frame();
    synced_compactions_ = compactions;
    return;
  }
  update(mesh, changed_slots(mesh.edges.changes.stamp, synced_frame_));
  synced_ = true;
  synced_frame_ = mesh.frame();
  synced_compactions_ = compactions;
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
  purge_dead();
  refit_touched();
  root_box_ = root_ == kNone ? Box{} : box_of(root_);
}

// ---- the tree

uint32_t SnapIndex::height() const {
  if (root_ == kNone) return 0;
  return uint32_t(height_of(root_)) + 1;
}

uint32_t SnapIndex::new_node() {
  if (!free_nodes_.empty()) {
    const uint32_t n = free_nodes_.back();
    free_nodes_.pop_back();
    return n;
  }
  grow(nodes_);
  grow(info_);
  nodes_.emplace_back();
  info_.push_back({});
  return static_cast<uint32_t>(nodes_.size() - 1);
}


SnapIndex::Box SnapIndex::box_of(uint32_t ref) const {
  if (ref & kLeafRef) return leaves_[ref & ~kLeafRef].box;
  Box b = nodes_[ref].box(0);
  merge_into(b, nodes_[ref].box(1));
  return b;
}

// Copies child s's boxes and references into n's entries; the child must be up to date.
void SnapIndex::fill_entries(Node& n, int s) const {
  const uint32_t c = n.child[s];
  if (c & kLeafRef) {
    const Box empty = {{kNaN, kNaN, kNaN}, {kNaN, kNaN, kNaN}};
    n.mid[2 * s] = c;
    n.mid[2 * s + 1] = kNone;
    n.set_entry(4 * s, c, leaves_[c & ~kLeafRef].box);
    for (int k = 1; k < 4; ++k) n.set_entry(4 * s + k, kNone, empty);
    return;
  }
  // Grandchild t's box is the union of the child's entries 2t and 2t+1, taken for all four at once: an
  // empty odd entry (NaN) loses the comparison and keeps the even one; both empty stay NaN.
  const Node& cn = nodes_[c];
  for (int a = 0; a < 3; ++a) {
    FloatQuad l[2], h[2];
    std::memcpy(l, cn.lo[a], sizeof l);
    std::memcpy(h, cn.hi[a], sizeof h);
    // __builtin_shufflevector: GCC (12 and later) and clang (the fuzz build) both have it.
    const FloatQuad le = __builtin_shufflevector(l[0], l[1], 0, 2, 4, 6), lo = __builtin_shufflevector(l[0], l[1], 1, 3, 5, 7);
    const FloatQuad he = __builtin_shufflevector(h[0], h[1], 0, 2, 4, 6), ho = __builtin_shufflevector(h[0], h[1], 1, 3, 5, 7);
    const FloatQuad lu = lo < le ? lo : le, hu = ho > he ? ho : he;
    std::memcpy(n.lo[a] + 4 * s, &lu, sizeof lu);
    std::memcpy(n.hi[a] + 4 * s, &hu, sizeof hu);
  }
  std::memcpy(n.entry + 4 * s, cn.mid, sizeof cn.mid);
  for (int j = 0; j < 2; ++j) n.mid[2 * s + j] = cn.child[j];
}

void SnapIndex::replace_child(uint32_t parent, uint32_t old_ref, uint32_t new_ref) {
  if (parent == kNone) {
    root_ = new_ref;
    return;
  }
  Node& p = nodes_[parent];
  const int s = p.child[0] == old_ref ? 0 : 1;
  p.child[s] = new_ref;
  fill(parent, s);
}

// Picks the sibling that adds the least box area over the path (the surface area heuristic, greedily
// down the tree), pairs the leaf with it under a new node and refits the path above.
void SnapIndex::insert_leaf(uint32_t leaf) {
  parent_of(leaf) = kNone;
  if (root_ == kNone) {
    root_ = leaf;
    return;
  }
  const Box lb = box_of(leaf);
  uint32_t i = root_;
  Box ib = box_of(root_);
  while (!(i & kLeafRef)) {
    const Node& n = nodes_[i];
    Box merged = ib;
    merge_into(merged, lb);
    const double combined = half_area(merged);
    const double here = 2 * combined, inherited = 2 * (combined - half_area(ib));
    const Box cb[2] = {n.box(0), n.box(1)};
    double cost[2];
    for (int s = 0; s < 2; ++s) {
      Box b = cb[s];
      merge_into(b, lb);
      cost[s] = half_area(b) + inherited - (n.child[s] & kLeafRef ? 0.0 : half_area(cb[s]));
    }
    if (here < cost[0] && here < cost[1]) break;
    const int s = cost[0] <= cost[1] ? 0 : 1;
    ib = cb[s];
    i = n.child[s];
  }
  const uint32_t sibling = i, old_parent = parent_of(sibling);
  const uint32_t p = new_node();
  nodes_[p].child[0] = sibling;
  nodes_[p].child[1] = leaf;
  fill(p, 0);
  fill(p, 1);
  info_[p].parent = old_parent;
  parent_of(sibling) = p;
  parent_of(leaf) = p;
  replace_child(old_parent, sibling, p);
  refit_path(p);
}

// Puts the leaf's sibling in its parent's place; boxes, heights and counts above wait for refit_touched().
// A subtree the sibling roots may itself be awaiting its refit, which refills the entries copied here.
void SnapIndex::remove_leaf(uint32_t leaf) {
  if (leaf == root_) {
    root_ = kNone;
    return;
  }
  const uint32_t p = parent_of(leaf), gp = info_[p].parent;
  const int s = nodes_[p].child[0] == leaf ? 1 : 0;
  const uint32_t sibling = nodes_[p].child[s];
  parent_of(sibling) = gp;
  replace_child(gp, p, sibling);
  free_nodes_.push_back(p);
  info_[p].parent = kFreed;
  if (gp != kNone) touched_.push_back(gp);
}

// Entries, heights and leaf counts from node i, whose own entries are right, to the root; then the
// highest subtree on the way grown too deep for its leaves is rebuilt. One insertion's refit: cheaper
// than refit_touched()'s marking for a single path, with the same result.
void SnapIndex::refit_path(uint32_t i) {
  uint32_t unbalanced = kNone;
  for (uint32_t below = kNone; i != kNone; below = i, i = info_[i].parent) {
    const Node& n = nodes_[i];
    if (below != kNone) fill(i, n.child[0] == below ? 0 : 1);
    Info& f = info_[i];
    f.height = 1 + std::max(height_of(n.child[0]), height_of(n.child[1]));
    f.leaves = leaves_of(n.child[0]) + leaves_of(n.child[1]);
    if (f.height > depth_limit(f.leaves)) unbalanced = i;
  }
  if (unbalanced != kNone) rebuild_subtree(unbalanced);
}

// Entries, heights and leaf counts from node i to the root.
void SnapIndex::refit_up(uint32_t i) {
  for (; i != kNone; i = info_[i].parent) {
    fill(i, 0);
    fill(i, 1);
    const Node& n = nodes_[i];
    info_[i].height = 1 + std::max(height_of(n.child[0]), height_of(n.child[1]));
    info_[i].leaves = leaves_of(n.child[0]) + leaves_of(n.child[1]);
  }
}

// One pass over the union of the paths from the touched nodes to the root, children before parents, so a
// curve's leaves, which share most of their paths, refit each shared node once. Then the highest subtrees
// grown too deep for their leaves are rebuilt.
void SnapIndex::refit_touched() {
  if (touched_.empty()) return;
  marked_list_.clear();
  for (uint32_t t : touched_) {
    if (info_[t].parent == kFreed) continue;
    for (; t != kNone && !info_[t].marked; t = info_[t].parent) {
      info_[t].marked = 1;
      marked_list_.push_back(t);
    }
  }
  touched_.clear();
  unbalanced_.clear();
  if (root_ != kNone && !(root_ & kLeafRef) && info_[root_].marked) refit_marked(root_, unbalanced_);
  for (uint32_t m : marked_list_) info_[m].marked = 0;
  for (uint32_t n : unbalanced_) rebuild_subtree(n);
}

void SnapIndex::refit_marked(uint32_t i, std::vector<uint32_t>& unbalanced) {
  const size_t below = unbalanced.size();
  Node& n = nodes_[i];
  for (int s = 0; s < 2; ++s) {
    const uint32_t c = n.child[s];
    if (c & kLeafRef || !info_[c].marked) continue;
    refit_marked(c, unbalanced);
    fill(i, s);
  }
  info_[i].height = 1 + std::max(height_of(n.child[0]), height_of(n.child[1]));
  info_[i].leaves = leaves_of(n.child[0]) + leaves_of(n.child[1]);
  if (info_[i].height > depth_limit(info_[i].leaves)) {
    unbalanced.resize(below);  // rebuilding this subtree rebuilds those inside it
    unbalanced.push_back(i);
  }
}

void SnapIndex::rebuild() {
  nodes_.clear();
  info_.clear();
  free_nodes_.clear();
  touched_.clear();
  free_leaves_.insert(free_leaves_.end(), dead_leaves_.begin(), dead_leaves_.end());
  dead_leaves_.clear();
  std::vector<Item> items;
  for (uint32_t r = 0; r < leaves_.size(); ++r)
    if (leaves_[r].edge != kNone) items.push_back({r | kLeafRef, leaves_[r].box});
  root_ = kNone;
  if (items.size() == 1) {
    root_ = items[0].ref;
    parent_of(root_) = kNone;
  } else if (items.size() > 1) {
    root_ = new_node();
    build(items, root_, kNone);
  }
}

// Rebuilds the subtree in place: `top` keeps its slot and its box, since it holds the same leaves.
void SnapIndex::rebuild_subtree(uint32_t top) {
  std::vector<Item> items;
  std::vector<uint32_t> stack = {top};
  while (!stack.empty()) {
    const uint32_t i = stack.back();
    stack.pop_back();
    for (int s = 0; s < 2; ++s) {
      const uint32_t c = nodes_[i].child[s];
      if (c & kLeafRef) items.push_back({c, box_of(c)});
      else stack.push_back(c);
    }
    if (i != top) free_nodes_.push_back(i);
  }
  build(items, top, info_[top].parent);
  refit_up(info_[top].parent);
}

// Top-down into inner node `node` (at least two items).
void SnapIndex::build(std::span<Item> items, uint32_t node, uint32_t parent) {
  info_[node].parent = parent;
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::numeric_limits<double>::infinity();
    hi[a] = -lo[a];
  }
  auto centre = [](const Item& it, int a) { return double(it.box.lo[a]) + double(it.box.hi[a]); };
  for (const Item& it : items)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], centre(it, a));
      hi[a] = std::max(hi[a], centre(it, a));
    }
  // Binned surface area heuristic: of the planes between 16 bins of box centres per axis, the one that
  // minimises area times count on both sides, among those that leave each side at least 30 % of the
  // items (so heights stay within depth_limit); the median of the widest axis when none does.
  constexpr int kBins = 16;
  const size_t count = items.size();
  int best_axis = -1, best_k = 0;
  double best_cost = std::numeric_limits<double>::infinity();
  auto bin_of = [&](const Item& it, int a) {  // written so that no value, NaN included, leaves the bins
    const double t = (centre(it, a) - lo[a]) * (kBins / (hi[a] - lo[a]));
    return t < kBins - 1 ? (t > 0 ? int(t) : 0) : kBins - 1;
  };
  constexpr float finf = std::numeric_limits<float>::infinity();
  const Box empty = {{finf, finf, finf}, {-finf, -finf, -finf}};
  for (int a = 0; a < 3 && count >= 4; ++a) {
    if (!(hi[a] > lo[a]) || !std::isfinite(hi[a] - lo[a])) continue;
    Box box[kBins];
    size_t n[kBins] = {};
    std::fill_n(box, kBins, empty);
    for (const Item& it : items) {
      const int b = bin_of(it, a);
      ++n[b];
      merge_into(box[b], it.box);
    }
    double left_area[kBins];
    size_t left_n[kBins];
    Box acc = empty;
    size_t c = 0;
    for (int k = 0; k < kBins; ++k) {
      merge_into(acc, box[k]);
      c += n[k];
      left_n[k] = c;
      left_area[k] = c ? half_area(acc) : 0.0;
    }
    acc = empty;
    c = 0;
    for (int k = kBins - 1; k > 0; --k) {
      merge_into(acc, box[k]);
      c += n[k];
      const size_t l = left_n[k - 1];
      if (10 * l < 3 * count || 10 * c < 3 * count) continue;
      const double cost = left_area[k - 1] * double(l) + half_area(acc) * double(c);
      if (cost < best_cost) best_cost = cost, best_axis = a, best_k = k;
    }
  }
  size_t mid;
  if (best_axis >= 0) {
    mid = size_t(std::partition(items.begin(), items.end(), [&](const Item& it) { return bin_of(it, best_axis) < best_k; }) -
                 items.begin());
  } else {
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
    mid = count / 2;
    std::nth_element(items.begin(), items.begin() + static_cast<std::ptrdiff_t>(mid), items.end(),
                     [&](const Item& x, const Item& y) { return centre(x, axis) < centre(y, axis); });
  }
  const std::span<Item> half[2] = {items.first(mid), items.subspan(mid)};
  for (int s = 0; s < 2; ++s) {
    uint32_t ref;
    if (half[s].size() == 1) {
      ref = half[s][0].ref;
      parent_of(ref) = node;
    } else {
      ref = new_node();
      build(half[s], ref, node);
    }
    nodes_[node].child[s] = ref;
    fill(node, s);
  }
  const Node& n = nodes_[node];
  info_[node].height = 1 + std::max(height_of(n.child[0]), height_of(n.child[1]));
  info_[node].leaves = leaves_of(n.child[0]) + leaves_of(n.child[1]);
}

// ---- queries

// Starts loading what a child reference points at while the current node is still being worked on.
void SnapIndex::prefetch(uint32_t ref) const {
  const char* at = ref & kLeafRef ? reinterpret_cast<const char*>(&leaves_[ref & ~kLeafRef])
                                   : reinterpret_cast<const char*>(&nodes_[ref]);
  const size_t bytes = ref & kLeafRef ? sizeof(Leaf) : sizeof(Node);
  for (size_t b = 0; b < bytes; b += 64) __builtin_prefetch(at + b);
}

namespace {

// A node's entry gaps, and which entry is nearest (an empty entry's NaN counts as farthest).
template <class Node>
[[gnu::always_inline]] inline int nearest_entry(const Node& n, const Vec3& p, double (&g)[8]) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  double key[8];
  for (int h = 0; h < 4; ++h) {
    const DoublePair gh = entry_gaps(n, h, p), kh = gh == gh ? gh : inf;
    g[2 * h] = gh[0], g[2 * h + 1] = gh[1];
    key[2 * h] = kh[0], key[2 * h + 1] = kh[1];
  }
  int m[4];
  for (int h = 0; h < 4; ++h) m[h] = key[2 * h + 1] < key[2 * h] ? 2 * h + 1 : 2 * h;
  const int a = key[m[1]] < key[m[0]] ? m[1] : m[0], b = key[m[3]] < key[m[2]] ? m[3] : m[2];
  return key[b] < key[a] ? b : a;
}

}  // namespace

SnapHit SnapIndex::nearest(const Vec3& p, double radius) const {
  SnapHit best;
  double bound = bound_of(radius);
  // Most queries far from the network end here, without reading the root's eight entries.
  if (root_ == kNone || squared_gap(root_box_, p) > bound) return best;
  auto visit = [&](const Leaf& l) {
    for (uint32_t k = 0; k < kLeafPoints; k += 2) {
      DoublePair x, y, z;
      std::memcpy(&x, l.x + k, sizeof x);
      std::memcpy(&y, l.y + k, sizeof y);
      std::memcpy(&z, l.z + k, sizeof z);
      const DoublePair dx = x - p.x(), dy = y - p.y(), dz = z - p.z();
      const auto near = dx * dx + dy * dy + dz * dz <= bound;
      for (uint32_t j = 0; j < 2; ++j) {
        if (!near[j]) continue;
        const double d = (Vec3(l.x[k + j], l.y[k + j], l.z[k + j]) - p).norm();
        if (d <= radius && before(d, l.edge, l.first + k + j, best)) {
          best = {EdgeIndex{l.edge}, l.first + k + j, d};
          bound = bound_of(d);
        }
      }
    }
  };
  struct Pending {
    uint32_t ref;
    double gap;
  };
  Pending stack[kStack];  // left uninitialised: a query must not pay for clearing it
  size_t top = 0;
  stack[top++] = {root_, 0.0};  // the root's entries or points are tested when it is popped
  while (top > 0) {
    const auto [ref, gap] = stack[--top];
    if (gap > bound) continue;
    if (ref & kLeafRef) {
      visit(leaves_[ref & ~kLeafRef]);
      continue;
    }
    const Node& n = nodes_[ref];
    double g[8];
    const int m = nearest_entry(n, p, g);
    // The nearest entry goes on top, so it is searched first and tightens the bound for the others.
    // Pushes are unconditional writes with a conditional count: which entry is nearest is a coin toss
    // that branches would mispredict.
    const size_t first = top;
    for (int k = 0; k < 8; ++k) {
      stack[top] = {n.entry[k], g[k]};
      top += k != m && g[k] <= bound;
    }
    stack[top] = {n.entry[m], g[m]};
    top += g[m] <= bound;
    for (size_t k = first; k < top; ++k) prefetch(stack[k].ref);
  }
  return best;
}

SnapHit SnapIndex::nearest_on_face(const Mesh& mesh, FaceIndex f, const Vec3& p, double radius) const {
  SnapHit best;
  double bound = bound_of(radius);
  // The exhaustive search's own order (loop order, then point order) with a strict comparison, so the
  // first of equally near points wins as there; boxes only skip runs that cannot reach the best so far.
  for (OrientedEdge oe : mesh.face_loop(f)) {
    const EdgeIndex e = edge_of(oe);
    if (e >= edge_leaves_.size()) continue;
    for (uint32_t r : edge_leaves_[e]) {
      const Leaf& l = leaves_[r];
      if (squared_gap(l.box, p) > bound) continue;
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
  uint32_t stack[kStack];
  size_t top = 0;
  if (squared_gap(box_of(root_), p) <= bound) stack[top++] = root_;
  while (top > 0) {
    const uint32_t ref = stack[--top];
    if (!(ref & kLeafRef)) {
      const Node& n = nodes_[ref];
      for (int h = 0; h < 4; ++h) {
        const DoublePair g = entry_gaps(n, h, p);
        for (int k = 0; k < 2; ++k)
          if (g[k] <= bound) stack[top++] = n.entry[2 * h + k];
      }
      continue;
    }
    const Leaf& l = leaves_[ref & ~kLeafRef];
    for (uint32_t k = 0; k < l.count; ++k) {
      const Vec3 q(l.x[k], l.y[k], l.z[k]);
      const double d = (q - p).norm();
      if (d <= radius) out.push_back({EdgeIndex{l.edge}, l.first + k, d});
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

namespace {
bool same_box(const float (&alo)[3], const float (&ahi)[3], const float (&blo)[3], const float (&bhi)[3]) {
  return std::equal(alo, alo + 3, blo) && std::equal(ahi, ahi + 3, bhi);
}
}  // namespace

std::string SnapIndex::validate_ref(uint32_t ref, uint32_t parent, const Box& box, size_t& leaves, size_t& dead) const {
  const Box own = box_of(ref);
  if (!same_box(own.lo, own.hi, box.lo, box.hi)) return "a box held by a parent is not its child's";
  if (ref & kLeafRef) {
    const Leaf& l = leaves_[ref & ~kLeafRef];
    if (l.parent != parent) return "a leaf record has a wrong parent";
    if (l.edge == kNone) {
      for (uint32_t k = 0; k < kLeafPoints; ++k)
        if (!std::isnan(l.x[k]) || !std::isnan(l.y[k]) || !std::isnan(l.z[k])) return "a dead leaf record has a point";
      ++dead;
      return "";
    }
    for (uint32_t k = 0; k < l.count; ++k) {
      const double q[3] = {l.x[k], l.y[k], l.z[k]};
      for (int a = 0; a < 3; ++a)
        if (q[a] < l.box.lo[a] || q[a] > l.box.hi[a]) return "a point lies outside its leaf's box";
    }
    ++leaves;
    return "";
  }
  if (info_[ref].parent != parent) return "node " + std::to_string(ref) + " has a wrong parent";
  const Node& n = nodes_[ref];
  // The entries must be what a refill from the children gives now (empty ones NaN: queries rely on it).
  Node want = n;
  fill_entries(want, 0);
  fill_entries(want, 1);
  if (std::memcmp(want.lo, n.lo, sizeof n.lo) || std::memcmp(want.hi, n.hi, sizeof n.hi) ||
      std::memcmp(want.entry, n.entry, sizeof n.entry) || std::memcmp(want.mid, n.mid, sizeof n.mid))
    return "node " + std::to_string(ref) + " holds stale entries";
  for (int s = 0; s < 2; ++s)
    if (auto why = validate_ref(n.child[s], ref, n.box(s), leaves, dead); !why.empty()) return why;
  if (info_[ref].height != 1 + std::max(height_of(n.child[0]), height_of(n.child[1])))
    return "node " + std::to_string(ref) + " has a wrong height";
  if (info_[ref].leaves != leaves_of(n.child[0]) + leaves_of(n.child[1]))
    return "node " + std::to_string(ref) + " has a wrong count";
  if (info_[ref].height > depth_limit(info_[ref].leaves)) return "node " + std::to_string(ref) + " is too deep for its leaves";
  return "";
}

std::string SnapIndex::validate(const Mesh& mesh) const {
  size_t points = 0, edges = 0;
  for (EdgeIndex e{0}; e < std::max<size_t>(mesh.edge_slots(), edge_leaves_.size()); ++e) {
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
  size_t leaves = 0, dead = 0;
  if (root_ != kNone)
    if (auto why = validate_ref(root_, kNone, box_of(root_), leaves, dead); !why.empty()) return why;
  if (root_ != kNone) {
    const Box b = box_of(root_);
    if (!same_box(b.lo, b.hi, root_box_.lo, root_box_.hi)) return "the root's box is stale";
  }
  if (dead != dead_leaves_.size()) return "the tree holds other dead leaf records than those listed";
  if (leaves + dead != leaves_.size() - free_leaves_.size()) return "the tree does not hold every leaf record";
  if (dead * 8 > leaves) return "dead leaf records were not purged";
  return "";
}

}  // namespace fire
