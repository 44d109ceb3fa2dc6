#pragma once
// The HUD, drawn with Dear ImGui over the presented frame: frame time, per-system timings, the counts,
// the sketch mode, the last rejected edit, the view toggles, the help overlay listing the keys, and in a live
// session the remotes' states and each IR camera's view; or, for fire aim, the camera views and their problems.
// It shows what the app hands it in HudData (engine data read by the app); it calls nothing of the engine.
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "engine/scheduler.hpp"
#include "platform/render/present.hpp"
#include "platform/window/window.hpp"

namespace fire::window {

// One IR camera's view: its blobs on the 1024 x 768 sensor image, and whether the pen is among them.
struct IrBlob {
  float x = 0, y = 0;  // sensor pixels
  int size = 0;        // the report's blob size, 0 to 15
  bool stray = false;  // a still light taken for a stray, not the pen (fire aim): drawn orange
};
struct CameraView {
  bool present = false;   // the camera has reported
  bool pen_seen = false;  // its last report shows a light
  std::vector<IrBlob> blobs;
  // fire aim: lines under the view's title (rate, battery, sensitivity), the stray lights named so far, and
  // where a rig's working volume lies in the image: `volume_columns` square cells a row, row by row, each
  // 0 (outside), 1 (seen by this camera only) or 2 (by both cameras); none without a rig.
  std::vector<std::string> lines;
  std::vector<IrBlob> strays;
  std::vector<uint8_t> volume;
  int volume_columns = 0;
};

struct HudData {
  double frame_ms = 0;       // wall time of the last displayed frame
  uint64_t frames = 0;       // system frames run (the scheduler's fixed step)
  const std::vector<SystemTiming>* timings = nullptr;
  const SystemTiming* frame_timing = nullptr;
  size_t vertices = 0, edges = 0, faces = 0, points = 0, surface_quads = 0;
  bool border_mode = true;   // no face yet, or a new part's border open: strokes extend the border; else they split faces
  size_t border_loops = 0;   // the surface's border loops: 0 once the object is closed
  size_t pending_bridges = 0;  // curves between two border loops waiting for their second: no surface there yet
  size_t pending_pieces = 0;   // pieces of strokes that ended off the network, waiting to be continued from their free end
  std::string last_rejection; // the last edit refused, in words; empty if none
  std::string status;         // a line of news (saved to, nothing to undo...)
  render::DrawOptions view;
  bool wireframe_supported = true;
  bool help = false;
  // A live session's news: the remotes' states and batteries, the mark to touch next; and each camera's view.
  std::vector<std::string> live;
  std::array<CameraView, 2> cameras;
  // fire aim: the HUD is the two camera views alone, as large as the window allows, with the `live` lines and
  // the problems (none: a line saying so).
  bool aiming = false;
  std::vector<std::string> problems;
  // The keys, one line each: the key, two or more spaces, what it does ("Ctrl+Z  undo"); the help overlay
  // shows them in two columns.
  std::vector<std::string> keys;
};

// A HUD window's rectangle, in window coordinates.
struct Panel {
  float x0, y0, x1, y1;
};

class Hud {
 public:
  // Installs ImGui's GLFW callbacks over the window's (they forward to them) and its Vulkan objects.
  static Result<std::unique_ptr<Hud>> create(render::Context& context, render::Presenter& presenter, Window& window);
  ~Hud();
  Hud(const Hud&) = delete;
  Hud& operator=(const Hud&) = delete;

  // Lays out this frame's HUD; the draw happens in draw(), inside the presenter's overlay pass.
  void build(const HudData& data);
  void draw(VkCommandBuffer cmd);
  // Whether window point (x, y) lies on one of the HUD's panels as last built: a press or a scroll there is the
  // HUD's, and the scene ignores it. By where each event lands, not by ImGui's WantCaptureMouse, which it
  // updates once a frame: a press on the panel and a drag on the scene within one frame would both go to
  // whichever had the pointer the frame before.
  bool covers(double x, double y) const;
  // A Vulkan call inside ImGui's backend failed (it reports through a callback that cannot return).
  Status status() const;

 private:
  Hud() = default;
  VkDevice device_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  bool glfw_ = false, vulkan_ = false;
  std::vector<Panel> panels_;  // the last build's windows
};

}  // namespace fire::window
