#pragma once
// What the scripted mouse drawings of `fire app` share (pawn_drawing, mug_drawing): the script's events, the view
// turned by right-drags computed with the app's own render::Orbit, and a stroke's path checked to show whole from
// that view by casting the rays the app's mouse pen will cast.
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "engine/common.hpp"
#include "platform/render/camera.hpp"
#include "systems/evaluate/evaluate.hpp"

namespace fire::test {

struct MouseDrawer {
  const evaluate::TriangleBvh& bvh;  // what the app's --reference draws on
  uint32_t width, height;
  render::Orbit orbit;  // the view as the script leaves it
  // The HUD's panel at the top left takes the mouse: no stroke may start or pass there. A press on it would also
  // hold the mouse for the frames ImGui takes to see it released, and the drags after it would be lost.
  float hud_right = 420, hud_bottom = 320;
  uint64_t frame = 2;
  std::ostringstream out{};

  void event(const std::string& text) { out << frame << ' ' << text << '\n'; }
  void move(float x, float y);

  // Whether the ray through `px` from `camera` meets the reference within 3 pixels (plus `slack`) of `expected`.
  bool seen(const render::Camera& camera, glm::vec2 px, const Vec3& expected, double slack) const;
  // Where each point lands in the image from `o`, the first on a whole pixel (a press takes the pointer's
  // position, which X keeps in whole pixels), the rest as the script writes them; fails when a point or the
  // surface between two of them is hidden, off the window or under the HUD.
  Result<std::vector<glm::vec2>> visible_path(const render::Orbit& o, const std::vector<Vec3>& points) const;

  // The drags (at most 400 pixels across and 150 down each, from the lower middle of the window, where
  // nothing takes the mouse) that turn `o` to yaw and pitch, rounded to whole pixels of the orbit's turn.
  struct Drag {
    int dx, dy;
  };
  static std::vector<Drag> drags_to(const render::Orbit& o, double yaw, double pitch);
  // The view those drags leave.
  render::Orbit turned(double yaw, double pitch) const;
  // Zooms the view in by `steps` of the wheel, the cursor where drags start.
  void zoom(float steps);
  // Turns the view to yaw and pitch with those drags.
  void turn(double yaw, double pitch);
  // The stroke through `pixels` (visible_path's from the current view): pen down on the first, a move to each of
  // the others, pen up.
  void draw(const std::vector<glm::vec2>& pixels);
};

}  // namespace fire::test
