#include "tests/platform/window/pawn_drawing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>
#include <vector>

#include "platform/render/camera.hpp"
#include "tools/app/app_window.hpp"

namespace fire::test {
namespace {

constexpr double kPi = std::numbers::pi;
double degrees(double d) { return d * kPi / 180; }

// The heights of the pawn's control loops 4, 8, 12, 16 and 20, the ones `network-from-mesh --unrefine 4`
// keeps: the top of the base, the neck's foot, the neck, the collar and the head.
constexpr double kRingHeights[] = {0.0817, 0.1456, 0.2493, 0.3291, 0.4475};
constexpr double kUndoneRingHeight = 0.20;
// Above this height the meridians follow rays from the axis at this height, so they reach the top's flat cap.
constexpr double kHeadCentre = 0.43;
// The pitches a view is tried at, after the current one: from a little above, where the neck shows under the
// collar, to higher, where the top does.
constexpr double kPitches[] = {0.35, 0.2, 0.5, 0.1, 0.65, 0.8};
// The HUD's panel at the top left takes the mouse: no stroke may start or pass there.
constexpr float kHudRight = 420, kHudBottom = 320;

struct Drawer {
  const evaluate::TriangleBvh& bvh;
  uint32_t width, height;
  render::Orbit orbit;
  Vec3 axis;  // a point on the pawn's axis at height 0
  uint64_t frame = 2;
  std::ostringstream out;

  void event(const std::string& text) { out << frame << ' ' << text << '\n'; }
  void move(float x, float y) {
    char text[64];
    std::snprintf(text, sizeof text, "move %.2f %.2f", x, y);
    event(text);
  }

  Result<Vec3> cast(const Vec3& origin, const Vec3& direction, const char* what) const {
    const evaluate::TriangleBvh::Hit hit = bvh.ray_cast(origin, direction.normalized());
    if (hit.triangle == evaluate::kNoTriangle) return Result<Vec3>::failure(std::string("no pawn ") + what);
    return hit.point;
  }
  // The pawn's surface at azimuth theta and height z, straight out from its axis.
  Result<Vec3> side(double theta, double z) const {
    return cast(axis + Vec3(0, 0, z), Vec3(std::cos(theta), std::sin(theta), 0), "at that height");
  }
  // Above kHeadCentre: the surface `phi` above the horizontal seen from the axis at that height.
  Result<Vec3> head(double theta, double phi) const {
    return cast(axis + Vec3(0, 0, kHeadCentre),
                Vec3(std::cos(phi) * std::cos(theta), std::cos(phi) * std::sin(theta), std::sin(phi)), "above the head centre");
  }

  // From the bottom at height z_from up to the top, or the other way.
  Result<std::vector<Vec3>> meridian(double theta, double z_from, bool downwards) const {
    std::vector<Vec3> points;
    for (double z = z_from; z < kHeadCentre; z += 0.004) {
      auto p = side(theta, z);
      if (!p) return Result<std::vector<Vec3>>::failure(p.error());
      points.push_back(*p);
    }
    for (int step = 0; step <= 30; ++step) {
      auto p = head(theta, degrees(3.0 * step));
      if (!p) return Result<std::vector<Vec3>>::failure(p.error());
      points.push_back(*p);
    }
    if (downwards) std::reverse(points.begin(), points.end());
    return points;
  }
  // Round the axis at height z from azimuth `from` to `to`, in steps of at most 2 degrees.
  Result<std::vector<Vec3>> ring(double z, double from, double to) const {
    const int steps = int(std::ceil(std::abs(to - from) / degrees(2)));
    std::vector<Vec3> points;
    for (int k = 0; k <= steps; ++k) {
      auto p = side(from + (to - from) * k / steps, z);
      if (!p) return Result<std::vector<Vec3>>::failure(p.error());
      points.push_back(*p);
    }
    return points;
  }

  // The drags (at most 400 pixels across and 150 down each, from the lower middle of the window, where
  // nothing takes the mouse) that turn `o` to yaw and pitch, rounded to whole pixels of the orbit's turn.
  struct Drag {
    int dx, dy;
  };
  static std::vector<Drag> drags_to(const render::Orbit& o, double yaw, double pitch) {
    const double per_pixel = render::kOrbitRadiansPerPixel;
    int dx = int(std::lround(std::remainder(double(o.yaw) - yaw, 2 * kPi) / per_pixel));  // a drag right turns yaw down
    int dy = int(std::lround((pitch - double(o.pitch)) / per_pixel));
    std::vector<Drag> drags;
    while (dx != 0 || dy != 0) {
      const int sx = std::clamp(dx, -400, 400), sy = std::clamp(dy, -150, 150);
      drags.push_back({sx, sy});
      dx -= sx;
      dy -= sy;
    }
    return drags;
  }

  // Where each point lands in the image from `o`, the first on a whole pixel (a press takes the pointer's
  // position, which X keeps in whole pixels), the rest as the script writes them; fails when a point or the
  // surface between two of them is hidden, off the window or under the HUD.
  Result<std::vector<glm::vec2>> visible_path(const render::Orbit& o, const std::vector<Vec3>& points) const {
    using R = Result<std::vector<glm::vec2>>;
    const render::Camera camera = render::orbit_camera(o, width, height);
    const Vec3 eye(camera.eye.x, camera.eye.y, camera.eye.z);
    std::vector<glm::vec2> pixels;
    for (size_t i = 0; i < points.size(); ++i) {
      glm::vec2 px = render::project_to_pixels(camera, points[i], width, height);
      px = i == 0 ? glm::round(px) : glm::round(px * 100.0f) / 100.0f;
      if (px.x < 1 || px.y < 1 || px.x > float(width) - 2 || px.y > float(height) - 2) return R::failure("off the window");
      if (px.x < kHudRight && px.y < kHudBottom) return R::failure("under the HUD");
      pixels.push_back(px);
    }
    auto seen = [&](glm::vec2 px, const Vec3& expected, double slack) {
      const glm::vec3 d = render::ray_through_pixel(camera, px, width, height);
      const evaluate::TriangleBvh::Hit hit = bvh.ray_cast(eye, Vec3(d.x, d.y, d.z));
      const glm::vec3 e(float(expected.x()), float(expected.y()), float(expected.z()));
      return hit.triangle != evaluate::kNoTriangle &&
             (hit.point - expected).norm() <= 3.0 * render::pixel_size_at(camera, e, height) + slack;
    };
    for (size_t i = 0; i < points.size(); ++i) {
      if (!seen(pixels[i], points[i], 0)) return R::failure("hidden");
      if (i + 1 < points.size() &&
          !seen((pixels[i] + pixels[i + 1]) * 0.5f, (points[i] + points[i + 1]) / 2, (points[i] - points[i + 1]).norm() / 2))
        return R::failure("hidden between two of its points");
    }
    return pixels;
  }

  // Turns the view to `yaw` at the current pitch, or else at the first of kPitches from which the whole
  // stroke shows, and draws it: pen down on the first point, a move to each of the others, pen up.
  Status stroke(const std::vector<Vec3>& points, double yaw, const std::string& name) {
    std::vector<double> pitches{double(orbit.pitch)};
    pitches.insert(pitches.end(), std::begin(kPitches), std::end(kPitches));
    std::string why;
    for (double pitch : pitches) {
      render::Orbit turned = orbit;
      const std::vector<Drag> drags = drags_to(orbit, yaw, pitch);
      for (const Drag& d : drags) turned.rotate(float(d.dx), float(d.dy));
      auto pixels = visible_path(turned, points);
      if (!pixels) {
        why = pixels.error();
        continue;
      }
      const int x0 = int(width / 2), y0 = int(height) * 3 / 4;
      for (const Drag& d : drags) {
        move(float(x0), float(y0));
        event("press right");
        move(float(x0 + d.dx), float(y0 + d.dy));
        event("release right");
      }
      if (!drags.empty()) ++frame;  // the app takes its camera from the orbit when it draws the frame
      orbit = turned;
      move(pixels->front().x, pixels->front().y);
      event("press left");
      for (size_t i = 1; i < pixels->size(); ++i) move((*pixels)[i].x, (*pixels)[i].y);
      event("release left");
      frame += 3;
      return Status::success();
    }
    return Status::failure(name + ": no view at yaw " + std::to_string(yaw) + " shows all of it (" + why + ")");
  }
};

}  // namespace

Result<PawnDrawing> pawn_drawing(const evaluate::TriangleMesh& reference, uint32_t width, uint32_t height) {
  using R = Result<PawnDrawing>;
  const evaluate::TriangleBvh bvh(reference);
  // The app frames the scene at the start: the reference alone, with no curves and no surface yet.
  const render::Box box = app::scene_box(Mesh{}, SurfaceLevels{}, reference.positions);
  Drawer d{bvh, width, height, render::frame_orbit(box, width, height),
           Vec3((box.lo.x + box.hi.x) / 2.0, (box.lo.y + box.hi.y) / 2.0, 0.0), 2, {}};
  d.out << "# generated by tests/platform/window/pawn_drawing.cpp\n";
  const double border_height = box.lo.z + 0.006;  // just above the pawn's open bottom ring, where rays still find it
  auto draw = [&](Result<std::vector<Vec3>> points, double yaw, const std::string& name) -> Status {
    if (!points) return Status::failure(name + ": " + points.error());
    return d.stroke(*points, yaw, name);
  };

  // The border: four quarters round the bottom, each seen from its middle; the last ends on the first's start.
  for (int quarter = 0; quarter < 4; ++quarter) {
    const double middle = degrees(90.0 * quarter);
    if (Status s = draw(d.ring(border_height, middle - degrees(45), middle + degrees(45)), middle,
                        "border quarter " + std::to_string(quarter + 1));
        !s)
      return R::failure(s.error);
  }
  // The first split goes over the top: up the meridian at -60 degrees and down the one at +60.
  {
    auto up = d.meridian(degrees(-60), border_height, false), down = d.meridian(degrees(60), border_height, true);
    if (!up || !down) return R::failure("the first split: " + (up ? down.error() : up.error()));
    up->insert(up->end(), down->begin() + 1, down->end());  // both pass through the top
    if (Status s = d.stroke(*up, 0.0, "the first split"); !s) return R::failure(s.error);
  }
  // The other meridians end on the top's vertex, which the first split made.
  for (double theta : {180.0, 120.0, 240.0, 0.0})
    if (Status s = draw(d.meridian(degrees(theta), border_height, false), degrees(theta),
                        "the meridian at " + std::to_string(int(theta)) + " degrees");
        !s)
      return R::failure(s.error);
  // Five ring arcs in each sector, each splitting the face it crosses.
  for (double from : {-60.0, 0.0, 60.0, 120.0, 180.0, 240.0})
    for (double z : kRingHeights)
      if (Status s = draw(d.ring(z, degrees(from), degrees(from + 60)), degrees(from + 30),
                          "the ring arc at height " + std::to_string(z) + " from " + std::to_string(int(from)) + " degrees");
          !s)
        return R::failure(s.error);
  if (Status s = draw(d.ring(kUndoneRingHeight, degrees(240), degrees(300)), degrees(270), "the arc to undo"); !s)
    return R::failure(s.error);
  d.event("key ctrl+z");
  d.frame += 30;  // the surface settles before it is exported
  d.event("key e");
  d.frame += 3;
  d.event("close");

  PawnDrawing drawing;
  drawing.script = d.out.str();
  drawing.faces = 6 * (std::size(kRingHeights) + 1);
  // Vertices: 4 where border strokes meet, 6 meridian feet, the top, 6 on each ring; a disk has V - E + F = 1.
  drawing.edges = 4 + 6 + 1 + 6 * std::size(kRingHeights) + drawing.faces - 1;
  return drawing;
}

}  // namespace fire::test
