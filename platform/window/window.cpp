#include "platform/window/window.hpp"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <cstdlib>

namespace fire::window {

namespace {

std::string g_glfw_error;  // the last error GLFW reported, for the message of a failed call

void on_glfw_error(int, const char* description) { g_glfw_error = description ? description : "(no description)"; }

Window* owner(GLFWwindow* w) { return static_cast<Window*>(glfwGetWindowUserPointer(w)); }

uint8_t to_mods(int mods) {
  return uint8_t(((mods & GLFW_MOD_SHIFT) ? kShift : 0) | ((mods & GLFW_MOD_CONTROL) ? kCtrl : 0));
}

Button to_button(int b) {
  return b == GLFW_MOUSE_BUTTON_RIGHT ? Button::Right : b == GLFW_MOUSE_BUTTON_MIDDLE ? Button::Middle : Button::Left;
}

int from_button(Button b) {
  return b == Button::Right ? GLFW_MOUSE_BUTTON_RIGHT : b == Button::Middle ? GLFW_MOUSE_BUTTON_MIDDLE : GLFW_MOUSE_BUTTON_LEFT;
}

// The events that carry two numbers and nothing else: a cursor position, a scroll offset.
void push_xy(GLFWwindow* w, WindowEventKind kind, double x, double y) {
  WindowEvent e;
  e.kind = kind;
  e.x = x;
  e.y = y;
  owner(w)->events().push_back(e);
}

void on_cursor(GLFWwindow* w, double x, double y) { push_xy(w, WindowEventKind::CursorMove, x, y); }

void on_button(GLFWwindow* w, int button, int action, int mods) {
  if (action != GLFW_PRESS && action != GLFW_RELEASE) return;
  WindowEvent e;
  e.kind = action == GLFW_PRESS ? WindowEventKind::ButtonPress : WindowEventKind::ButtonRelease;
  glfwGetCursorPos(w, &e.x, &e.y);
  e.button = to_button(button);
  e.mods = to_mods(mods);
  owner(w)->events().push_back(e);
}

void on_scroll(GLFWwindow* w, double dx, double dy) { push_xy(w, WindowEventKind::Scroll, dx, dy); }

void on_key(GLFWwindow* w, int key, int, int action, int mods) {
  if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
  WindowEvent e;
  e.kind = WindowEventKind::KeyPress;
  e.key = key;
  e.mods = to_mods(mods);
  owner(w)->events().push_back(e);
}

void on_close(GLFWwindow* w) {
  WindowEvent e;
  e.kind = WindowEventKind::Close;
  owner(w)->events().push_back(e);
}

}  // namespace

Result<std::unique_ptr<Window>> Window::create(const std::string& title, uint32_t width, uint32_t height) {
  using R = Result<std::unique_ptr<Window>>;
  glfwSetErrorCallback(on_glfw_error);
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((!display || !*display) && (!wayland || !*wayland))
    return R::failure("no display (neither DISPLAY nor WAYLAND_DISPLAY is set): the app needs a window; "
                      "use `fire render` to render without one");
  if (!glfwInit())
    return R::failure("cannot open the display (" + g_glfw_error + "); use `fire render` to render without one");
  if (!glfwVulkanSupported()) {
    glfwTerminate();
    return R::failure("GLFW finds no Vulkan loader or no driver that can draw into a window (Debian packages "
                      "libvulkan1, and mesa-vulkan-drivers for lavapipe without a GPU)");
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
  std::unique_ptr<Window> w(new Window);
  w->window_ = glfwCreateWindow(int(width), int(height), title.c_str(), nullptr, nullptr);
  if (!w->window_) {
    glfwTerminate();
    return R::failure("glfwCreateWindow failed: " + g_glfw_error);
  }
  glfwSetWindowUserPointer(w->window_, w.get());
  glfwSetCursorPosCallback(w->window_, on_cursor);
  glfwSetMouseButtonCallback(w->window_, on_button);
  glfwSetScrollCallback(w->window_, on_scroll);
  glfwSetKeyCallback(w->window_, on_key);
  glfwSetWindowCloseCallback(w->window_, on_close);
  return w;
}

Window::~Window() {
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
}

render::ContextOptions Window::context_options() const {
  render::ContextOptions options;
  uint32_t count = 0;
  const char** names = glfwGetRequiredInstanceExtensions(&count);
  for (uint32_t i = 0; names && i < count; ++i) options.instance_extensions.emplace_back(names[i]);
  options.can_present = [](VkInstance instance, VkPhysicalDevice device, uint32_t family) {
    return glfwGetPhysicalDevicePresentationSupport(instance, device, family) == GLFW_TRUE;
  };
  return options;
}

Result<VkSurfaceKHR> Window::create_surface(VkInstance instance) const {
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  const VkResult r = glfwCreateWindowSurface(instance, window_, nullptr, &surface);
  if (r != VK_SUCCESS) return Result<VkSurfaceKHR>::failure(render::vk_failure("glfwCreateWindowSurface", r));
  return surface;
}

void Window::poll() { glfwPollEvents(); }

bool Window::should_close() const { return glfwWindowShouldClose(window_); }

void Window::framebuffer_size(uint32_t& width, uint32_t& height) const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  width = uint32_t(std::max(w, 0));
  height = uint32_t(std::max(h, 0));
}

void Window::request_size(uint32_t width, uint32_t height) { glfwSetWindowSize(window_, int(width), int(height)); }

void Window::inject(const WindowEvent& e) {
  // Reads back what GLFW would call: setting a callback returns the one installed.
  auto installed = [this](auto set) {
    auto callback = set(window_, nullptr);
    set(window_, callback);
    return callback;
  };
  const int mods = ((e.mods & kShift) ? GLFW_MOD_SHIFT : 0) | ((e.mods & kCtrl) ? GLFW_MOD_CONTROL : 0);
  switch (e.kind) {
    case WindowEventKind::CursorMove:
      glfwSetCursorPos(window_, e.x, e.y);  // the real pointer, which the HUD polls; GLFW reports no warp of its own
      if (auto cb = installed(glfwSetCursorPosCallback)) cb(window_, e.x, e.y);
      break;
    case WindowEventKind::ButtonPress:
    case WindowEventKind::ButtonRelease:
      if (auto cb = installed(glfwSetMouseButtonCallback))
        cb(window_, from_button(e.button), e.kind == WindowEventKind::ButtonPress ? GLFW_PRESS : GLFW_RELEASE, mods);
      break;
    case WindowEventKind::Scroll:
      if (auto cb = installed(glfwSetScrollCallback)) cb(window_, e.x, e.y);
      break;
    case WindowEventKind::KeyPress:
      if (auto cb = installed(glfwSetKeyCallback)) {
        cb(window_, e.key, glfwGetKeyScancode(e.key), GLFW_PRESS, mods);
        cb(window_, e.key, glfwGetKeyScancode(e.key), GLFW_RELEASE, mods);
      }
      break;
    case WindowEventKind::Close:
      // What the window manager's close button does: the flag, then the close callback.
      glfwSetWindowShouldClose(window_, GLFW_TRUE);
      if (auto cb = installed(glfwSetWindowCloseCallback)) cb(window_);
      break;
  }
}

}  // namespace fire::window
