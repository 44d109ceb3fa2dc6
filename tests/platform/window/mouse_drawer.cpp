#include "tests/platform/window/mouse_drawer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace fire::test {

void MouseDrawer::move(float x, float y) {
  char text[64];
  std::snprintf(text, sizeof text, "move %.2f %.2f", x, y);
  event(text);
}

bool MouseDrawer::seen(const render::Camera& camera, glm::vec2 px, const Vec3& expected, double slack) const {
  const Vec3 eye(camera.eye.x, camera.eye.y, camera.eye.z);
  const glm::vec3 d = render::ray_through_pixel(camera, px, width, height);
  const evaluate::TriangleBvh::Hit hit = bvh.ray_cast(eye, Vec3(d.x, d.y, d.z));
  const glm::vec3 e(float(expected.x()), float(expected.y()), float(expected.z()));
  return hit.triangle != evaluate::kNoTriangle &&
         (hit.point - expected).norm() <= 3.0 * render::pixel_size_at(camera, e, height) + slack;
}

Result<std::vector<glm::vec2>> MouseDrawer::visible_path(const render::Orbit& o, const std::vector<Vec3>& points) const {
  using R = Result<std::vector<glm::vec2>>;
  const render::Camera camera = render::orbit_camera(o, width, height);
  std::vector<glm::vec2> pixels;
  for (size_t i = 0; i < points.size(); ++i) {
    glm::vec2 px = render::project_to_pixels(camera, points[i], width, height);
    px = i == 0 ? glm::round(px) : glm::round(px * 100.0f) / 100.0f;
    if (px.x < 1 || px.y < 1 || px.x > float(width) - 2 || px.y > float(height) - 2) return R::failure("off the window");
    if (px.x < hud_right && px.y < hud_bottom) return R::failure("under the HUD");
    pixels.push_back(px);
  }
  for (size_t i = 0; i < points.size(); ++i) {
    if (!seen(camera, pixels[i], points[i], 0)) return R::failure("hidden");
    if (i + 1 < points.size() && !seen(camera, (pixels[i] + pixels[i + 1]) * 0.5f, (points[i] + points[i + 1]) / 2,
                                       (points[i] - points[i + 1]).norm() / 2))
      return R::failure("hidden between two of its points");
  }
  return pixels;
}

std::vector<MouseDrawer::Drag> MouseDrawer::drags_to(const render::Orbit& o, double yaw, double pitch) {
  const double per_pixel = render::kOrbitRadiansPerPixel;
  // A drag right turns yaw down.
  int dx = int(std::lround(std::remainder(double(o.yaw) - yaw, 2 * std::numbers::pi) / per_pixel));
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

render::Orbit MouseDrawer::turned(double yaw, double pitch) const {
  render::Orbit o = orbit;
  for (const Drag& d : drags_to(orbit, yaw, pitch)) o.rotate(float(d.dx), float(d.dy));
  return o;
}

void MouseDrawer::zoom(float steps) {
  move(float(width / 2), float(height * 3 / 4));
  char text[32];
  std::snprintf(text, sizeof text, "scroll %g", double(steps));
  event(text);
  orbit.zoom(steps);
  ++frame;
}

void MouseDrawer::turn(double yaw, double pitch) {
  const std::vector<Drag> drags = drags_to(orbit, yaw, pitch);
  const int x0 = int(width / 2), y0 = int(height) * 3 / 4;
  for (const Drag& d : drags) {
    move(float(x0), float(y0));
    event("press right");
    move(float(x0 + d.dx), float(y0 + d.dy));
    event("release right");
    orbit.rotate(float(d.dx), float(d.dy));
  }
  if (!drags.empty()) ++frame;  // the app takes its camera from the orbit when it draws the frame
}

void MouseDrawer::draw(const std::vector<glm::vec2>& pixels) {
  move(pixels.front().x, pixels.front().y);
  event("press left");
  for (size_t i = 1; i < pixels.size(); ++i) move(pixels[i].x, pixels[i].y);
  event("release left");
  frame += 3;
}

}  // namespace fire::test
