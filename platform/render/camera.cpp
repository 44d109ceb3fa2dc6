#include "platform/render/camera.hpp"

#include <algorithm>
#include <cmath>

namespace fire::render {

Result<View> parse_view(const std::string& name) {
  if (name == "iso") return View::Iso;
  if (name == "front") return View::Front;
  if (name == "top") return View::Top;
  if (name == "side") return View::Side;
  if (name == "bottom") return View::Bottom;
  return Result<View>::failure("--view must be iso, front, top, side or bottom, not '" + name + "'");
}

Camera frame_box(const Box& box, View view, uint32_t width, uint32_t height) {
  glm::vec3 lo = box.empty() ? glm::vec3(-1.0f) : box.lo, hi = box.empty() ? glm::vec3(1.0f) : box.hi;
  const glm::vec3 center = (lo + hi) * 0.5f;
  const float radius = std::max(glm::length(hi - lo) * 0.5f, 1e-6f);
  glm::vec3 back{0.0f, -1.0f, 0.0f}, up{0.0f, 0.0f, 1.0f};  // from the centre towards the eye
  switch (view) {
    case View::Iso: back = glm::normalize(glm::vec3(1.0f, -1.0f, 0.8f)); break;
    case View::Front: break;
    case View::Side: back = {1.0f, 0.0f, 0.0f}; break;
    case View::Top: back = {0.0f, 0.0f, 1.0f}, up = {0.0f, 1.0f, 0.0f}; break;
    case View::Bottom: back = {0.0f, 0.0f, -1.0f}, up = {0.0f, 1.0f, 0.0f}; break;
  }
  const glm::vec3 right = glm::normalize(glm::cross(up, back));
  const glm::vec3 true_up = glm::cross(back, right);

  const float fov_y = glm::radians(30.0f);
  const float aspect = float(width) / float(std::max(height, 1u));
  const float margin = 0.88f;  // the box's image fills at most this fraction of the viewport
  const float tan_y = std::tan(fov_y * 0.5f) * margin, tan_x = tan_y * aspect;
  // Distance from the centre: each corner at depth d - z (z towards the eye) must satisfy
  // |x| <= (d - z) tan_x and |y| <= (d - z) tan_y.
  float distance = 0.0f;
  for (int c = 0; c < 8; ++c) {
    glm::vec3 p{(c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z};
    glm::vec3 q = p - center;
    float x = glm::dot(q, right), y = glm::dot(q, true_up), z = glm::dot(q, back);
    distance = std::max({distance, z + std::abs(x) / tan_x, z + std::abs(y) / tan_y});
  }
  distance = std::max(distance, radius * 1.05f);

  Camera camera;
  camera.eye = center + back * distance;
  camera.view = glm::lookAt(camera.eye, center, true_up);
  const float near_plane = std::max(distance - radius * 1.5f, distance * 0.02f);
  const float far_plane = distance + radius * 2.0f;
  camera.projection = glm::perspective(fov_y, aspect, near_plane, far_plane);
  // d(depth)/d(eye distance) of a 0..1 perspective depth at the box's centre.
  const float slope = far_plane * near_plane / ((far_plane - near_plane) * distance * distance);
  camera.line_depth_pull = slope * 0.01f * radius;
  camera.projection[1][1] *= -1.0f;  // Vulkan's clip space has y pointing down
  // Perspective makes the box's near side look larger, so its image is off centre: shift and zoom the image
  // plane (a lens shift, the view direction stays) so the projected corners are centred and fill `margin`.
  glm::vec2 ndc_lo(1e30f), ndc_hi(-1e30f);
  for (int c = 0; c < 8; ++c) {
    glm::vec4 q = camera.projection * camera.view *
                  glm::vec4((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z, 1.0f);
    glm::vec2 n = glm::vec2(q) / q.w;
    ndc_lo = glm::min(ndc_lo, n);
    ndc_hi = glm::max(ndc_hi, n);
  }
  const glm::vec2 mid = (ndc_lo + ndc_hi) * 0.5f, half = glm::max((ndc_hi - ndc_lo) * 0.5f, glm::vec2(1e-6f));
  const float zoom = margin / std::max(half.x, half.y);
  glm::mat4 shift(1.0f);
  shift[0][0] = shift[1][1] = zoom;
  shift[3][0] = -zoom * mid.x;
  shift[3][1] = -zoom * mid.y;
  camera.projection = shift * camera.projection;
  camera.key_light = glm::normalize(0.6f * back + 0.9f * true_up - 0.6f * right);
  return camera;
}

namespace {
constexpr float kOrbitFovY = 0.5235988f;  // 30 degrees, as frame_box
glm::vec3 orbit_back(const Orbit& o) {
  return {std::cos(o.pitch) * std::cos(o.yaw), std::cos(o.pitch) * std::sin(o.yaw), std::sin(o.pitch)};
}
}  // namespace

void Orbit::rotate(float dx, float dy) {
  yaw -= dx * kOrbitRadiansPerPixel;
  pitch = std::clamp(pitch + dy * kOrbitRadiansPerPixel, -1.55f, 1.55f);  // short of the poles, where Z-up turns over
}

void Orbit::pan(float dx, float dy, uint32_t height) {
  const glm::vec3 back = orbit_back(*this);
  const glm::vec3 right = glm::normalize(glm::cross(glm::vec3(0.0f, 0.0f, 1.0f), back));
  const glm::vec3 up = glm::cross(back, right);
  // One pixel at the target's depth, so the point under the cursor follows it.
  const float pixel = 2.0f * distance * std::tan(kOrbitFovY * 0.5f) / float(std::max(height, 1u));
  target += (-dx * right + dy * up) * pixel;
}

void Orbit::zoom(float steps) { distance = std::clamp(distance * std::pow(0.88f, steps), radius * 0.05f, radius * 40.0f); }

Orbit frame_orbit(const Box& box, uint32_t width, uint32_t height) {
  glm::vec3 lo = box.empty() ? glm::vec3(-1.0f) : box.lo, hi = box.empty() ? glm::vec3(1.0f) : box.hi;
  Orbit o;
  o.target = (lo + hi) * 0.5f;
  o.radius = std::max(glm::length(hi - lo) * 0.5f, 1e-6f);
  o.yaw = -0.7853982f;                            // the iso view's direction (1, -1, 0.8)
  o.pitch = std::atan2(0.8f, std::sqrt(2.0f));
  const float aspect = float(width) / float(std::max(height, 1u));
  const float tan_y = std::tan(kOrbitFovY * 0.5f) * 0.88f, tan_min = std::min(tan_y, tan_y * aspect);
  o.distance = std::max(o.radius / tan_min, o.radius * 1.05f);
  return o;
}

Camera orbit_camera(const Orbit& o, uint32_t width, uint32_t height) {
  const glm::vec3 back = orbit_back(o);
  const glm::vec3 right = glm::normalize(glm::cross(glm::vec3(0.0f, 0.0f, 1.0f), back));
  const glm::vec3 up = glm::cross(back, right);
  Camera camera;
  camera.eye = o.target + back * o.distance;
  camera.view = glm::lookAt(camera.eye, o.target, up);
  const float near_plane = std::max(o.distance - o.radius * 2.0f, o.distance * 0.01f);
  const float far_plane = o.distance + o.radius * 2.0f;
  camera.projection = glm::perspective(kOrbitFovY, float(width) / float(std::max(height, 1u)), near_plane, far_plane);
  const float slope = far_plane * near_plane / ((far_plane - near_plane) * o.distance * o.distance);
  camera.line_depth_pull = slope * 0.01f * o.radius;
  camera.projection[1][1] *= -1.0f;  // Vulkan's clip space has y pointing down
  camera.key_light = glm::normalize(0.6f * back + 0.9f * up - 0.6f * right);
  return camera;
}

float pixel_size_at(const Camera& camera, const glm::vec3& p, uint32_t height) {
  const float depth = -(camera.view * glm::vec4(p, 1.0f)).z;  // along the view direction
  // projection[1][1] is 1 / tan(fov_y / 2), negated for Vulkan's y; a lens shift does not change it.
  return 2.0f * std::max(depth, 0.0f) / (std::abs(camera.projection[1][1]) * float(std::max(height, 1u)));
}

glm::vec3 ray_through_pixel(const Camera& camera, glm::vec2 pixel, uint32_t width, uint32_t height) {
  const glm::vec2 ndc(pixel.x / float(std::max(width, 1u)) * 2.0f - 1.0f, pixel.y / float(std::max(height, 1u)) * 2.0f - 1.0f);
  const glm::vec4 far_point = glm::inverse(camera.view_projection()) * glm::vec4(ndc, 1.0f, 1.0f);
  return glm::normalize(glm::vec3(far_point) / far_point.w - camera.eye);
}

glm::vec2 project_to_pixels(const Camera& camera, const Vec3& p, uint32_t width, uint32_t height) {
  glm::vec4 c = camera.view_projection() * glm::vec4(float(p.x()), float(p.y()), float(p.z()), 1.0f);
  return {(c.x / c.w * 0.5f + 0.5f) * float(width), (c.y / c.w * 0.5f + 0.5f) * float(height)};
}

}  // namespace fire::render
