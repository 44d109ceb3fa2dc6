#pragma once
// Viewpoints framing an axis-aligned box (Z is up, as in the drawing rig's world frame).
#include <span>
#include <string>

#include "engine/common.hpp"
#include "platform/render/glm.hpp"

namespace fire::render {

enum class View { Iso, Front, Top, Side, Bottom };

// "iso", "front", "top", "side", "bottom" (from below: what rests on the table); a failure otherwise.
Result<View> parse_view(const std::string& name);

struct Box {
  glm::vec3 lo{1e30f}, hi{-1e30f};
  void add(const Vec3& p) {
    glm::vec3 q(float(p.x()), float(p.y()), float(p.z()));
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }
  bool empty() const { return lo.x > hi.x; }
};

struct Camera {
  glm::mat4 view{1.0f}, projection{1.0f};  // projection: Vulkan clip space (y down, depth 0..1)
  glm::vec3 eye{0.0f};
  glm::vec3 key_light{0.0f, 0.0f, 1.0f};  // direction towards the key light, above and left of the viewer
  // Clip-space depth by which curves are pulled towards the viewer so they show on the surface they
  // lie on: the depth of 1% of the framed box's radius at its centre.
  float line_depth_pull = 0.0f;
  glm::mat4 view_projection() const { return projection * view; }
};

// A perspective camera looking at `box` from the view's direction, close enough that the box fills
// most of the image and far enough that every corner stays inside it.
Camera frame_box(const Box& box, View view, uint32_t width, uint32_t height);

// How far a drag of one pixel turns the orbit (yaw and pitch), radians.
inline constexpr float kOrbitRadiansPerPixel = 0.008f;

// The app's camera: orbits `target` at `distance`, `yaw` about Z from +X, `pitch` above the XY plane.
struct Orbit {
  glm::vec3 target{0.0f};
  float distance = 1.0f, yaw = 0.0f, pitch = 0.0f;
  float radius = 1.0f;  // of the scene: sets the depth range and how far curves are pulled towards the viewer
  // Mouse gestures, in window pixels.
  void rotate(float dx, float dy);
  void pan(float dx, float dy, uint32_t height);
  void zoom(float steps);  // positive: closer
};
// The iso view of `box`, at the distance that frame_box would choose for it.
Orbit frame_orbit(const Box& box, uint32_t width, uint32_t height);
Camera orbit_camera(const Orbit& orbit, uint32_t width, uint32_t height);

// The model length one pixel spans at p's depth (a perspective camera): a radius in pixels in model units.
float pixel_size_at(const Camera& camera, const glm::vec3& p, uint32_t height);
// The unit direction from camera.eye through a point of the image given in pixels from the top-left corner.
glm::vec3 ray_through_pixel(const Camera& camera, glm::vec2 pixel, uint32_t width, uint32_t height);

// Where a world point lands in the image, in pixels from the top-left corner.
glm::vec2 project_to_pixels(const Camera& camera, const Vec3& p, uint32_t width, uint32_t height);

}  // namespace fire::render
