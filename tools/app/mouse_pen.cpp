#include "tools/app/mouse_pen.hpp"

#include <cmath>

#include "engine/input_log.hpp"
#include "platform/render/camera.hpp"
#include "tools/app/app_window.hpp"

namespace fire::app {

MousePen::MousePen(AppWindow& app, const evaluate::TriangleBvh* reference, double snap_px)
    : app_(app), reference_(reference), snap_px_(snap_px) {}

std::pair<Vec3, Vec3> MousePen::cursor_ray(glm::vec2 pixel) const {
  const render::Camera& camera = app_.camera();
  const glm::vec3 d = render::ray_through_pixel(camera, pixel, app_.width(), app_.height());
  return {Vec3(camera.eye.x, camera.eye.y, camera.eye.z), Vec3(d.x, d.y, d.z)};
}

std::optional<Vec3> MousePen::hit_mesh(const evaluate::TriangleBvh& bvh, glm::vec2 pixel) const {
  const auto [origin, direction] = cursor_ray(pixel);
  const evaluate::TriangleBvh::Hit hit = bvh.ray_cast(origin, direction);
  if (hit.triangle == evaluate::kNoTriangle) return std::nullopt;
  return hit.point;
}

std::optional<Vec3> MousePen::hit_plane(glm::vec2 pixel) const {
  const auto [origin, direction] = cursor_ray(pixel);
  const double facing = direction.dot(plane_normal_);
  if (std::abs(facing) < 1e-9) return std::nullopt;
  const double t = (plane_point_ - origin).dot(plane_normal_) / facing;
  if (!(t > 0)) return std::nullopt;
  return Vec3(origin + t * direction);
}

namespace {

evaluate::TriangleMesh surface_triangles(const SurfaceLevels& surface) {
  evaluate::TriangleMesh mesh{surface.positions, {}};
  mesh.triangles.reserve(surface.quads.size() / 4 * 6);
  for (size_t q = 0; q + 3 < surface.quads.size(); q += 4) {
    const uint32_t* v = &surface.quads[q];
    mesh.triangles.insert(mesh.triangles.end(), {v[0], v[1], v[2], v[0], v[2], v[3]});
  }
  return mesh;
}

}  // namespace

std::optional<Vec3> MousePen::point_under(glm::vec2 pixel, const SurfaceLevels& surface) const {
  if (reference_) return hit_mesh(*reference_, pixel);
  if (surface.empty()) return std::nullopt;
  return hit_mesh(evaluate::TriangleBvh(surface_triangles(surface)), pixel);
}

bool MousePen::begin(glm::vec2 pixel, const SurfaceLevels& surface, const glm::vec3& view_target) {
  if (reference_) {
    stroke_mesh_ = reference_;
    return hit_mesh(*reference_, pixel).has_value();
  }
  stroke_mesh_ = nullptr;
  if (!surface.empty()) {
    surface_bvh_.emplace(surface_triangles(surface));
    if (hit_mesh(*surface_bvh_, pixel)) {
      stroke_mesh_ = &*surface_bvh_;
      return true;
    }
  }
  const render::Camera& camera = app_.camera();
  plane_point_ = Vec3(view_target.x, view_target.y, view_target.z);
  plane_normal_ = (plane_point_ - Vec3(camera.eye.x, camera.eye.y, camera.eye.z)).normalized();
  return hit_plane(pixel).has_value();
}

bool MousePen::sample(glm::vec2 pixel) {
  const std::optional<Vec3> hit = stroke_mesh_ ? hit_mesh(*stroke_mesh_, pixel) : hit_plane(pixel);
  if (!hit) return false;
  InputEvent e;
  e.kind = EventKind::Pen;
  e.p = *hit;
  const glm::vec3 p(float(hit->x()), float(hit->y()), float(hit->z()));
  e.snap = snap_px_ * double(render::pixel_size_at(app_.camera(), p, app_.height()));
  app_.log_event(std::move(e));
  return true;
}

}  // namespace fire::app
