#include "tests/platform/window/mug_drawing.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include "systems/synth/network_from_mesh.hpp"
#include "tests/platform/window/mouse_drawer.hpp"
#include "tools/app/app_window.hpp"
#include "tools/simulation/drawing_plan.hpp"

namespace fire::test {
namespace {

using simulation::Chain;
using simulation::DrawingNetwork;
using simulation::PlanStep;

// The network drawn: network_from_mesh's at this --unrefine, finer where the mouse needs it (mouse_network).
constexpr uint32_t kUnrefine = 2;
// The views: the first view's yaw turned in 24 steps about the up axis, at these pitches (radians).
constexpr int kYawSteps = 24;
constexpr double kPitches[] = {-0.6, -0.25, 0.1, 0.35, 0.6, 0.85, 1.1, 1.35};
// A point is drawn only where the view meets the surface at least this steeply (the cosine of the angle between
// the ray and the surface's normal): along a grazing ray, the pixel a press rounds to lands far from the point.
constexpr double kSteepest = 0.3;
// How far inside the border its strokes are drawn, as a fraction of the scene's diagonal: a ray to a point on the
// surface's edge misses it as often as not.
constexpr double kBorderInset = 0.002;
// Scroll steps in before drawing: a finer pixel on the object, and snap radii of a few pixels under the clearance
// the plan keeps between a stroke drawn in pieces and the other curves.
constexpr float kZoomSteps = 3;
// The HUD's panel grows down while a bridge or pieces of a stroke wait (a wrapped line each) and with the last
// status line.
constexpr float kHudRight = 440, kHudBottom = 470;
// The pitch of the last view, a little above the horizon.
constexpr double kScreenshotPitch = 0.35;
// The split stroke undone (Ctrl+Z) and drawn again, as the simulated person does.
constexpr int kUndoAfter = 3;
// The longest loop of curves looked for around a hole's centre.
constexpr size_t kMaxCapCurves = 8;

struct View {
  double yaw, pitch;
};

// A loop's points, their plane and how far they reach from its centroid: what the sketch's face_under judges a
// picked point by.
struct Loop {
  std::vector<Vec3> points;
  LoopPlane plane;
  Vec3 u, v;  // a basis of the plane
  double extent = 0;
  explicit Loop(std::vector<Vec3> p) : points(std::move(p)), plane(loop_plane(points)) {
    u = plane.normal.unitOrthogonal();
    v = plane.normal.cross(u);
    for (const Vec3& q : points) extent = std::max(extent, (q - plane.centroid).norm());
  }
  // How far inside the loop p projects (negative: outside), in its plane.
  double depth_inside(const Vec3& p) const {
    auto plane_xy = [&](const Vec3& q) { return Eigen::Vector2d((q - plane.centroid).dot(u), (q - plane.centroid).dot(v)); };
    const Eigen::Vector2d x = plane_xy(p);
    bool inside = false;
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t i = 0, j = points.size() - 1; i < points.size(); j = i++) {
      const Eigen::Vector2d a = plane_xy(points[i]), b = plane_xy(points[j]);
      if ((a.y() > x.y()) != (b.y() > x.y()) && x.x() < b.x() + (x.y() - b.y()) * (a.x() - b.x()) / (a.y() - b.y())) inside = !inside;
      const Eigen::Vector2d ab = b - a;
      const double t = ab.squaredNorm() > 0 ? std::clamp((x - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
      nearest = std::min(nearest, (a + t * ab - x).norm());
    }
    return inside ? nearest : -nearest;
  }
  double height(const Vec3& p) const { return std::abs((p - plane.centroid).dot(plane.normal)); }
};

// Union-find over indices.
struct Sets {
  std::vector<uint32_t> parent;
  explicit Sets(size_t n) : parent(n) {
    for (uint32_t i = 0; i < n; ++i) parent[i] = i;
  }
  uint32_t find(uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(uint32_t a, uint32_t b) { parent[find(a)] = find(b); }
};

// The faces beside each curve of `net`.
std::vector<std::vector<uint32_t>> faces_beside(const DrawingNetwork& net) {
  std::vector<std::vector<uint32_t>> beside(net.curves.size());
  for (uint32_t f = 0; f < net.faces.size(); ++f)
    for (const simulation::Leg& l : net.faces[f]) beside[l.curve].push_back(f);
  return beside;
}

// `net` with only the curves `keep` marks, its faces merged across the others. Fails where a merged face is not
// bounded by one loop.
Result<DrawingNetwork> merged(const DrawingNetwork& net, const std::vector<char>& keep) {
  using R = Result<DrawingNetwork>;
  const std::vector<std::vector<uint32_t>> beside = faces_beside(net);
  Sets regions(net.faces.size());
  for (uint32_t k = 0; k < net.curves.size(); ++k)
    if (!keep[k] && beside[k].size() == 2) regions.join(beside[k][0], beside[k][1]);
  DrawingNetwork out;
  out.vertices = net.vertices;
  std::vector<uint32_t> curve_of(net.curves.size(), 0);
  for (uint32_t k = 0; k < net.curves.size(); ++k)
    if (keep[k]) curve_of[k] = uint32_t(out.curves.size()), out.curves.push_back(net.curves[k]);
  std::vector<std::vector<simulation::Leg>> legs(net.faces.size());
  for (uint32_t f = 0; f < net.faces.size(); ++f)
    for (const simulation::Leg& l : net.faces[f])
      if (keep[l.curve]) legs[regions.find(f)].push_back({curve_of[l.curve], l.forward});
  auto start = [&](const simulation::Leg& l) { return l.forward ? out.curves[l.curve].a : out.curves[l.curve].b; };
  auto end = [&](const simulation::Leg& l) { return l.forward ? out.curves[l.curve].b : out.curves[l.curve].a; };
  for (const std::vector<simulation::Leg>& region : legs) {
    if (region.empty()) continue;
    Chain& face = out.faces.emplace_back(1, region.front());
    while (face.size() < region.size() && end(face.back()) != start(face.front())) {
      const auto next = std::find_if(region.begin(), region.end(), [&](const simulation::Leg& l) { return start(l) == end(face.back()); });
      if (next == region.end()) return R::failure("a merged face's curves do not close");
      face.push_back(*next);
    }
    if (face.size() != region.size() || end(face.back()) != start(face.front())) return R::failure("a merged face is not bounded by one loop");
  }
  return out;
}

// The network the mouse can draw: `net` without the inner curves that a face other than the two beside them holds
// both ends of, those two faces merged (again until there is none). Such a curve is drawn as a split of the one
// face then, and the sketch tells which face a stroke goes into only from a tracked pen's cameras: from the mouse,
// the nearest face takes it, and of equals the lowest (the mug's handle: a tube two curves round at --unrefine 2,
// whose rings join those two).
Result<DrawingNetwork> mouse_network(DrawingNetwork net) {
  for (;;) {
    std::vector<std::vector<uint32_t>> corners(net.faces.size());
    for (uint32_t f = 0; f < net.faces.size(); ++f)
      for (const simulation::Leg& l : net.faces[f]) corners[f].push_back(net.curves[l.curve].a), corners[f].push_back(net.curves[l.curve].b);
    const std::vector<std::vector<uint32_t>> beside = faces_beside(net);
    std::vector<char> keep(net.curves.size(), 1);
    for (uint32_t k = 0; k < net.curves.size(); ++k)
      for (uint32_t g = 0; g < net.faces.size() && keep[k] && beside[k].size() == 2; ++g) {
        auto holds = [&](uint32_t v) { return std::find(corners[g].begin(), corners[g].end(), v) != corners[g].end(); };
        keep[k] = std::find(beside[k].begin(), beside[k].end(), g) != beside[k].end() || !holds(net.curves[k].a) ||
                  !holds(net.curves[k].b);
      }
    if (std::all_of(keep.begin(), keep.end(), [](char c) { return c != 0; })) return net;
    Result<DrawingNetwork> fewer = merged(net, keep);
    if (!fewer) return fewer;
    net = std::move(*fewer);
  }
}

// The network as the mouse draws it: the border's curves moved `inset` into the surface, and the other curves
// that end on the border cut `inset` short of it; a stroke's end lands on the border's vertex, which lies within
// the snap radius.
DrawingNetwork inset_border(DrawingNetwork net, const evaluate::TriangleBvh& bvh, double inset) {
  std::vector<char> on_border(net.vertices.size(), 0);
  for (const simulation::DrawingCurve& c : net.curves)
    if (c.border) on_border[c.a] = on_border[c.b] = 1;
  std::vector<int> face_of(net.curves.size(), -1);
  for (size_t f = 0; f < net.faces.size(); ++f)
    for (const simulation::Leg& l : net.faces[f]) face_of[l.curve] = int(f);
  for (simulation::DrawingCurve& c : net.curves) {
    if (c.border) {
      // Toward the middle of the face beside it, along the surface.
      Vec3 middle = Vec3::Zero();
      const std::vector<Vec3> loop = simulation::chain_points(net, net.faces[size_t(face_of[&c - net.curves.data()])]);
      for (const Vec3& p : loop) middle += p;
      middle /= double(loop.size());
      for (Vec3& p : c.points) p = bvh.closest(p + inset * (middle - p).normalized()).point;
      continue;
    }
    // The point `inset` along the curve from the end at `first`, on the surface, in place of the ones before it.
    auto cut = [&](auto first, auto last) {
      double along = 0;
      for (auto p = first; std::next(p) != last; ++p) {
        const double step = (*std::next(p) - *p).norm();
        if (along + step >= inset) {
          const Vec3 at = bvh.closest(*p + (inset - along) / step * (*std::next(p) - *p)).point;
          *p = at;
          return p;
        }
        along += step;
      }
      return first;
    };
    if (on_border[c.b]) c.points.erase(cut(c.points.rbegin(), c.points.rend()).base(), c.points.end());
    if (on_border[c.a]) c.points.erase(c.points.begin(), cut(c.points.begin(), c.points.end()));
  }
  return net;
}

// The views the plan picks from, what each shows, and the strokes and holes drawn from them.
struct Planner {
  const DrawingNetwork& net;
  const evaluate::TriangleMesh& reference;
  MouseDrawer& drawer;
  std::vector<View> views;
  std::vector<Vec3> backs;                          // each view's direction from the target to the eye
  std::vector<std::vector<std::vector<char>>> seen;  // view, curve, point

  Vec3 back(const View& v) const {
    return Vec3(std::cos(v.pitch) * std::cos(v.yaw), std::cos(v.pitch) * std::sin(v.yaw), std::sin(v.pitch));
  }
  render::Orbit orbit(const View& v) const {
    render::Orbit o = drawer.orbit;
    o.yaw = float(v.yaw);
    o.pitch = float(v.pitch);
    return o;
  }
  // The views nearest `current` first.
  std::vector<int> order(int current) const {
    std::vector<int> out(views.size());
    for (size_t j = 0; j < views.size(); ++j) out[j] = int(j);
    std::stable_sort(out.begin(), out.end(), [&](int a, int b) {
      return backs[size_t(a)].dot(backs[size_t(current)]) > backs[size_t(b)].dot(backs[size_t(current)]);
    });
    return out;
  }
  // Whether the reference faces the ray through `px` steeply enough where it meets it.
  bool steep(const render::Camera& camera, glm::vec2 px) const {
    const glm::vec3 d = render::ray_through_pixel(camera, px, drawer.width, drawer.height);
    const Vec3 ray = Vec3(d.x, d.y, d.z).normalized();
    const evaluate::TriangleBvh::Hit hit = drawer.bvh.ray_cast(Vec3(camera.eye.x, camera.eye.y, camera.eye.z), ray);
    if (hit.triangle == evaluate::kNoTriangle) return false;
    const uint32_t* t = &reference.triangles[3 * size_t(hit.triangle)];
    const Vec3 normal =
        (reference.positions[t[1]] - reference.positions[t[0]]).cross(reference.positions[t[2]] - reference.positions[t[0]]).normalized();
    return std::abs(normal.dot(ray)) >= kSteepest;
  }
  void see_all() {
    for (int k = 0; k < kYawSteps; ++k)
      for (double pitch : kPitches) {
        views.push_back({double(drawer.orbit.yaw) + 2 * std::numbers::pi * k / kYawSteps, pitch});
        backs.push_back(back(views.back()));
      }
    seen.assign(views.size(), {});
    for (size_t j = 0; j < views.size(); ++j) {
      const render::Camera camera = render::orbit_camera(orbit(views[j]), drawer.width, drawer.height);
      for (const simulation::DrawingCurve& c : net.curves) {
        std::vector<glm::vec2> px;
        for (const Vec3& p : c.points) px.push_back(render::project_to_pixels(camera, p, drawer.width, drawer.height));
        std::vector<char>& s = seen[j].emplace_back(c.points.size(), 0);
        for (size_t i = 0; i < c.points.size(); ++i) {
          const glm::vec2 q = px[i];
          s[i] = q.x >= 2 && q.y >= 2 && q.x <= float(drawer.width) - 3 && q.y <= float(drawer.height) - 3 &&
                 !(q.x < drawer.hud_right + 1 && q.y < drawer.hud_bottom + 1) && drawer.seen(camera, q, c.points[i], 0) &&
                 ((i > 0 && i + 1 < c.points.size()) || steep(camera, q));
          // The surface up to the next point too, as visible_path checks it.
          if (s[i] && i + 1 < c.points.size())
            s[i] = drawer.seen(camera, (q + px[i + 1]) * 0.5f, (c.points[i] + c.points[i + 1]) / 2,
                               (c.points[i] - c.points[i + 1]).norm() / 2);
        }
      }
    }
  }
  // Draws a planned stroke from its view, or else the nearest one that shows it whole once the view is turned there
  // (a drag turns the view by whole pixels).
  Status stroke(const std::vector<Vec3>& points, int view, const std::string& name) {
    std::string why;
    for (int j : order(view)) {
      auto pixels = drawer.visible_path(drawer.turned(views[size_t(j)].yaw, views[size_t(j)].pitch), points);
      if (!pixels) {
        why = pixels.error();
        continue;
      }
      drawer.turn(views[size_t(j)].yaw, views[size_t(j)].pitch);
      drawer.draw(*pixels);
      return Status::success();
    }
    return Status::failure(name + ": " + why);
  }

  // The loop of curves around a hole the plan opens (a cap): the one whose points' mean is the hole's point, as
  // the plan places it (simulation::chain_points over the cap's loop).
  std::optional<Chain> cap_around(const Vec3& centre) const {
    std::vector<std::vector<uint32_t>> at(net.vertices.size());
    for (uint32_t k = 0; k < net.curves.size(); ++k) {
      at[net.curves[k].a].push_back(k);
      at[net.curves[k].b].push_back(k);
    }
    auto end = [&](const simulation::Leg& l) { return l.forward ? net.curves[l.curve].b : net.curves[l.curve].a; };
    std::optional<Chain> best;
    double best_off = std::numeric_limits<double>::infinity();
    // Each simple cycle from its lowest vertex.
    for (uint32_t start = 0; start < net.vertices.size(); ++start) {
      std::vector<Chain> stack{{}};
      while (!stack.empty()) {
        const Chain c = std::move(stack.back());
        stack.pop_back();
        for (uint32_t k : at[c.empty() ? start : end(c.back())]) {
          Chain next = c;
          next.push_back({k, net.curves[k].a == (c.empty() ? start : end(c.back()))});
          const uint32_t w = end(next.back());
          if (w == start && next.size() >= 3) {
            const std::vector<Vec3> points = simulation::chain_points(net, next);
            Vec3 mean = Vec3::Zero();
            for (const Vec3& p : points) mean += p;
            if (const double off = (mean / double(points.size()) - centre).norm(); off < best_off) best_off = off, best = next;
          } else if (w > start && next.size() < kMaxCapCurves &&
                     std::none_of(c.begin(), c.end(), [&](const simulation::Leg& l) { return end(l) == w; })) {
            stack.push_back(std::move(next));
          }
        }
      }
    }
    return best;
  }

  // A loop of legs (a face's boundary, in any order) as its points in order, each polyline's last point left out
  // as Mesh::face_boundary leaves it out.
  Loop loop_of(const std::vector<simulation::Leg>& legs) const {
    auto start = [&](const simulation::Leg& l) { return l.forward ? net.curves[l.curve].a : net.curves[l.curve].b; };
    auto end = [&](const simulation::Leg& l) { return l.forward ? net.curves[l.curve].b : net.curves[l.curve].a; };
    std::vector<char> used(legs.size(), 0);
    std::vector<Vec3> points;
    for (size_t i = 0, n = 0; n < legs.size(); ++n) {
      used[i] = 1;
      std::vector<Vec3> line = net.curves[legs[i].curve].points;
      if (!legs[i].forward) std::reverse(line.begin(), line.end());
      points.insert(points.end(), line.begin(), line.end() - 1);
      for (size_t j = 0; j < legs.size(); ++j)
        if (!used[j] && start(legs[j]) == end(legs[i])) {
          i = j;
          break;
        }
    }
    return Loop(std::move(points));
  }

  // The faces the sketch holds after the curves `drawn`: the network's faces merged across the curves not drawn
  // yet, but for the far side (bounded only by caps' curves: it gets surface last), and the caps drawn round and not
  // opened yet. The cap `target`'s loop first.
  std::vector<Loop> sketch_faces(const std::vector<char>& drawn, const std::vector<Chain>& caps, size_t target) const {
    std::vector<Loop> faces;
    std::vector<char> on_cap(net.curves.size(), 0);
    for (size_t c = target; c < caps.size(); ++c) {
      bool closed = true;
      std::vector<simulation::Leg> legs(caps[c].begin(), caps[c].end());
      for (const simulation::Leg& l : legs) closed = closed && drawn[l.curve];
      if (closed) faces.push_back(loop_of(legs));
    }
    for (const Chain& cap : caps)
      for (const simulation::Leg& l : cap) on_cap[l.curve] = 1;
    const std::vector<std::vector<uint32_t>> beside = faces_beside(net);
    Sets regions(net.faces.size());
    for (uint32_t k = 0; k < net.curves.size(); ++k)
      if (!drawn[k] && beside[k].size() == 2) regions.join(beside[k][0], beside[k][1]);
    std::vector<std::vector<simulation::Leg>> legs(net.faces.size());
    for (uint32_t f = 0; f < net.faces.size(); ++f)
      for (const simulation::Leg& l : net.faces[f])
        if (drawn[l.curve] && !(beside[l.curve].size() == 2 && regions.find(beside[l.curve][0]) == regions.find(beside[l.curve][1])))
          legs[regions.find(f)].push_back(l);
    for (const std::vector<simulation::Leg>& region : legs)
      if (!region.empty() && !std::all_of(region.begin(), region.end(), [&](const simulation::Leg& l) { return on_cap[l.curve] != 0; }))
        faces.push_back(loop_of(region));
    return faces;
  }

  // Opens the hole in `faces`' first (a cap, sketch_faces'): O with the cursor on the reference where the sketch
  // picks that face (face_under: the point lies over its loop, seen along the loop's normal, and nearest its plane
  // of the faces it lies over), with the widest margin of the views, to the loop's edge and to the other faces.
  Status hole(const std::vector<Loop>& faces, int view, const std::string& name) {
    const Loop& cap = faces.front();
    struct Candidate {
      double bound;  // the margin to the cap alone, which the whole margin cannot exceed
      int view;
      glm::vec2 px;
      Vec3 point;
    };
    std::vector<Candidate> candidates;
    for (int j : order(view)) {
      const render::Camera camera =
          render::orbit_camera(drawer.turned(views[size_t(j)].yaw, views[size_t(j)].pitch), drawer.width, drawer.height);
      const Vec3 eye(camera.eye.x, camera.eye.y, camera.eye.z);
      const Vec3& c = cap.plane.centroid;
      const glm::vec2 centre = render::project_to_pixels(camera, c, drawer.width, drawer.height);
      const float reach = float(cap.extent) / render::pixel_size_at(camera, glm::vec3(float(c.x()), float(c.y()), float(c.z())), drawer.height);
      const float step = std::max(1.0f, reach / 40);
      for (float dy = -reach; dy <= reach; dy += step)
        for (float dx = -reach; dx <= reach; dx += step) {
          const glm::vec2 px = glm::round(centre + glm::vec2(dx, dy));
          if (px.x < 1 || px.y < 1 || px.x > float(drawer.width) - 2 || px.y > float(drawer.height) - 2 ||
              (px.x < drawer.hud_right && px.y < drawer.hud_bottom))
            continue;
          const glm::vec3 d = render::ray_through_pixel(camera, px, drawer.width, drawer.height);
          const evaluate::TriangleBvh::Hit hit = drawer.bvh.ray_cast(eye, Vec3(d.x, d.y, d.z));
          if (hit.triangle == evaluate::kNoTriangle) continue;
          const double bound = std::min(cap.depth_inside(hit.point), cap.extent - cap.height(hit.point));
          if (bound > 0) candidates.push_back({bound, j, px, hit.point});
        }
    }
    std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) { return a.bound > b.bound; });
    // The margin to each other face: above it farther than the cap, outside it, or farther off its plane than its size.
    const Candidate* best = nullptr;
    double best_margin = 0;
    for (const Candidate& c : candidates) {
      if (c.bound <= best_margin) break;
      double margin = c.bound;
      const double height = cap.height(c.point);
      for (size_t f = 1; f < faces.size() && margin > best_margin; ++f) {
        const Loop& other = faces[f];
        const double h = other.height(c.point);
        margin = std::min(margin, std::max({h - height, -other.depth_inside(c.point), h - other.extent}));
      }
      if (margin > best_margin) best_margin = margin, best = &c;
    }
    if (!best) return Status::failure(name + ": no view shows a point of the reference the sketch would take for the face to open");
    drawer.turn(views[size_t(best->view)].yaw, views[size_t(best->view)].pitch);
    drawer.move(best->px.x, best->px.y);
    drawer.event("key o");
    drawer.frame += 3;
    return Status::success();
  }
};

}  // namespace

Result<MouseDrawing> mouse_drawing(const PolygonMeshView& control, const evaluate::TriangleMesh& reference, uint32_t width, uint32_t height) {
  using R = Result<MouseDrawing>;
  const evaluate::TriangleBvh bvh(reference);
  // The app frames the scene at the start: the reference alone, with no curves and no surface yet.
  const render::Box box = app::scene_box(Mesh{}, SurfaceLevels{}, reference.positions);
  MouseDrawer drawer{bvh, width, height, render::frame_orbit(box, width, height)};
  drawer.hud_right = kHudRight;
  drawer.hud_bottom = kHudBottom;
  Result<Mesh> network = network_from_mesh(control, UnrefineOptions{.unrefine = kUnrefine, .limit = true});
  if (!network) return R::failure("the network: " + network.error());
  Result<DrawingNetwork> mouse = mouse_network(simulation::drawing_network(*network));
  if (!mouse) return R::failure("the network: " + mouse.error());
  const DrawingNetwork net = inset_border(std::move(*mouse), bvh, kBorderInset * double(glm::length(box.hi - box.lo)));
  drawer.out << "# generated by tests/platform/window/mug_drawing.cpp\n";
  drawer.zoom(kZoomSteps);
  Planner planner{net, reference, drawer, {}, {}, {}};
  planner.see_all();
  simulation::PoseQuestions questions;
  questions.order = [&](int current) { return planner.order(current); };
  questions.sees = [&](int view, uint32_t curve, size_t point) { return planner.seen[size_t(view)][curve][point] != 0; };
  Result<simulation::DrawingPlan> plan = simulation::plan_drawing(net, questions, 0, kUndoAfter);
  if (!plan) return R::failure("the plan: " + plan.error());
  std::vector<Chain> caps;
  for (size_t i = 0; i < plan->steps.size(); ++i)
    if (plan->steps[i].kind == PlanStep::Kind::Hole) {
      std::optional<Chain> cap = planner.cap_around(plan->steps[i].points.front());
      if (!cap) return R::failure("the hole of step " + std::to_string(i + 1) + ": no loop of curves around it");
      caps.push_back(std::move(*cap));
    }

  MouseDrawing drawing;
  std::vector<char> drawn(net.curves.size(), 0), stroke_end(net.vertices.size(), 0);
  for (size_t i = 0; i < plan->steps.size(); ++i) {
    const PlanStep& step = plan->steps[i];
    const std::string name = "step " + std::to_string(i + 1) + " of " + std::to_string(plan->steps.size());
    switch (step.kind) {
      case PlanStep::Kind::Register:
        break;
      case PlanStep::Kind::Stroke: {
        if (Status s = planner.stroke(step.points, step.pose, "the stroke of " + name); !s) return R::failure(s.error);
        for (uint32_t k = 0; k < net.curves.size(); ++k) {
          const simulation::DrawingCurve& c = net.curves[k];
          drawn[k] = drawn[k] || std::find(step.points.begin(), step.points.end(), c.points[c.points.size() / 2]) != step.points.end();
          for (const Vec3& end : {step.points.front(), step.points.back()}) {
            if (end == c.points.front()) stroke_end[c.a] = 1;
            if (end == c.points.back()) stroke_end[c.b] = 1;
          }
        }
        ++drawing.strokes;
        break;
      }
      case PlanStep::Kind::Undo:  // the plan draws the stroke again next
        drawer.event("key ctrl+z");
        drawer.frame += 3;
        break;
      case PlanStep::Kind::Hole:
        if (Status s = planner.hole(planner.sketch_faces(drawn, caps, size_t(drawing.holes)), step.pose, "the hole of " + name); !s)
          return R::failure(s.error);
        ++drawing.holes;
        break;
      case PlanStep::Kind::Sharp:
        return R::failure("the sharp curve of " + name + ": marking curves sharp is not scripted");
    }
  }
  drawer.frame += 30;  // the surface settles before it is exported
  drawer.event("key e");
  drawer.turn(planner.views.front().yaw, kScreenshotPitch);  // the last frame, the screenshot, from the app's first view
  drawer.frame += 3;
  drawer.event("close");

  drawing.script = drawer.out.str();
  drawing.pieces = plan->pieces;
  drawing.faces = uint32_t(net.faces.size());
  // A vertex where only two curves meet joins them into one edge unless a stroke ended there.
  std::vector<uint32_t> valence(net.vertices.size(), 0);
  for (const simulation::DrawingCurve& c : net.curves) ++valence[c.a], ++valence[c.b];
  drawing.edges = uint32_t(net.curves.size());
  for (uint32_t v = 0; v < net.vertices.size(); ++v) drawing.edges -= valence[v] == 2 && !stroke_end[v];
  return drawing;
}

}  // namespace fire::test
