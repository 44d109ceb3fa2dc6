#pragma once
// The app's window (GLFW, no client API: Vulkan draws into it through platform/render/present.hpp).
//
// Input arrives through GLFW's callbacks, which queue WindowEvents for the app to drain once per frame.
// The HUD (hud.hpp) installs its own callbacks over these and forwards to them, so a click the HUD takes is
// still seen here; the app asks the HUD whether to ignore it.
// A test drives the window with inject(): it calls the callbacks GLFW has installed, as GLFW does on a
// real event, and moves the real cursor, so the app sees the same calls either way.
#include <vulkan/vulkan.h>

#include <memory>
#include <string>
#include <vector>

#include "engine/common.hpp"
#include "platform/render/context.hpp"

struct GLFWwindow;

namespace fire::window {

enum class WindowEventKind : uint8_t { CursorMove, ButtonPress, ButtonRelease, Scroll, KeyPress, Close };
enum class Button : uint8_t { Left, Right, Middle };
// Key modifiers, as flags.
inline constexpr uint8_t kShift = 1, kCtrl = 2;

struct WindowEvent {
  WindowEventKind kind = WindowEventKind::CursorMove;
  double x = 0, y = 0;       // cursor position in window pixels; Scroll: x, y offsets
  Button button = Button::Left;
  int key = 0;               // KeyPress: the GLFW key code (GLFW_KEY_*), layout independent
  uint8_t mods = 0;          // kShift | kCtrl
};

class Window {
 public:
  // Fails with a message (never a crash) when there is no display to open a window on.
  static Result<std::unique_ptr<Window>> create(const std::string& title, uint32_t width, uint32_t height);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  // What the Vulkan context needs for this window: instance extensions and a present test.
  render::ContextOptions context_options() const;
  // A surface for `instance`, to hand to render::Presenter.
  Result<VkSurfaceKHR> create_surface(VkInstance instance) const;

  // Processes the window system's events: callbacks queue them in events().
  void poll();
  std::vector<WindowEvent>& events() { return events_; }
  bool should_close() const;
  // The drawable size in pixels (0 x 0 while minimised).
  void framebuffer_size(uint32_t& width, uint32_t& height) const;
  GLFWwindow* handle() const { return window_; }

  // A scripted event through the callbacks GLFW installed (the HUD's, then ours), the cursor moved first.
  void inject(const WindowEvent& event);
  // Asks the window system for a new size (it may refuse or adjust it); the swapchain follows.
  void request_size(uint32_t width, uint32_t height);

 private:
  Window() = default;
  GLFWwindow* window_ = nullptr;
  std::vector<WindowEvent> events_;
};

}  // namespace fire::window
