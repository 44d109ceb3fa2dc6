#pragma once
// The mouse as the pen of `fire app`: it draws on the reference mesh; without one, on the surface where
// the stroke starts on it, or else on the plane through the view's centre facing the view, kept for the
// whole stroke. Every hit is a logged pen sample carrying the snap radius of `snap_px` at its depth,
// so the drawing replays without the view.
#include <optional>
#include <utility>

#include <glm/glm.hpp>

#include "engine/common.hpp"
#include "engine/surface.hpp"
#include "systems/evaluate/evaluate.hpp"

namespace fire::app {

class AppWindow;

class MousePen {
 public:
  // `reference`: the mesh strokes draw on, or null.
  MousePen(AppWindow& app, const evaluate::TriangleBvh* reference, double snap_px);
  // Chooses what the stroke starting at `pixel` draws on: false when it would draw on nothing. `surface`
  // is the surface as the stroke begins; `view_target` the point the view turns about.
  bool begin(glm::vec2 pixel, const SurfaceLevels& surface, const glm::vec3& view_target);
  // The point under `pixel` on the reference, or without one on `surface`: what a command picks a face by.
  std::optional<Vec3> point_under(glm::vec2 pixel, const SurfaceLevels& surface) const;
  // Logs a pen sample where `pixel` hits what the stroke draws on; false when it hits nothing.
  bool sample(glm::vec2 pixel);

 private:
  std::pair<Vec3, Vec3> cursor_ray(glm::vec2 pixel) const;
  std::optional<Vec3> hit_mesh(const evaluate::TriangleBvh& bvh, glm::vec2 pixel) const;
  std::optional<Vec3> hit_plane(glm::vec2 pixel) const;

  AppWindow& app_;
  const evaluate::TriangleBvh* reference_;
  double snap_px_;
  std::optional<evaluate::TriangleBvh> surface_bvh_;  // the surface as the stroke began
  const evaluate::TriangleBvh* stroke_mesh_ = nullptr;
  Vec3 plane_point_ = Vec3::Zero(), plane_normal_ = Vec3::UnitZ();
};

}  // namespace fire::app
