#pragma once
// The present path, beside the offscreen one: the renderer's frame drawn straight into a window's swapchain
// image (the renderer made with RenderSettings::color_format = format()), an overlay (the app's HUD) drawn
// over it in a render pass, then presented with FIFO, i.e. vsync, which paces the display.
//
// One frame in flight: the renderer has one target and host-visible buffers that upload() writes, so a
// frame waits for the previous one (wait()) before anything of the renderer is touched.
// A swapchain that is out of date (the window was resized) or has no area (minimised): frame() returns false
// and the caller resizes with the window's current size.
// The window system is not known here: the caller makes the VkSurfaceKHR (GLFW) and hands it over.
#include <functional>
#include <memory>
#include <vector>

#include "platform/render/renderer.hpp"

namespace fire::render {

// What Presenter::frame did with a frame it drew.
enum class Presented { Shown, SwapchainStale };

class Presenter {
 public:
  // Takes ownership of `surface`, made from context.instance(); width and height are the window's in pixels.
  static Result<std::unique_ptr<Presenter>> create(Context& context, VkSurfaceKHR surface, uint32_t width,
                                                   uint32_t height);
  ~Presenter();
  Presenter(const Presenter&) = delete;
  Presenter& operator=(const Presenter&) = delete;

  // Waits for the previous frame's commands, after which the renderer's buffers may be written.
  Status wait();
  // Draws over the scene, inside overlay_pass().
  using Overlay = std::function<void(VkCommandBuffer)>;
  // Acquires an image, records the renderer's frame (resized to the swapchain first if needed) and the
  // overlay, submits and presents. swapchain_stale: the swapchain no longer fits the window (out of date,
  // suboptimal or minimised; the frame may or may not have been shown), call resize(). With `capture`, a frame
  // that was presented is read back into it (RGBA, top row first), waiting for the frame.
  Result<Presented> frame(Renderer& renderer, const Camera& camera, const DrawOptions& options, const Overlay& overlay,
                     Image* capture = nullptr);
  // Recreates the swapchain for a window of this size; at a zero size (minimised) frame() shows nothing
  // until a later call.
  Status resize(uint32_t width, uint32_t height);
  // Commands recorded once and waited for (the HUD's font upload).
  Status run_once(const std::function<void(VkCommandBuffer)>& record);

  VkRenderPass overlay_pass() const { return overlay_pass_; }
  VkFormat format() const { return format_.format; }  // of the window's images: the renderer must draw in it
  // Whether the window's images encode to sRGB on write (colours drawn into them are then linear).
  bool srgb() const { return format_.format == VK_FORMAT_B8G8R8A8_SRGB || format_.format == VK_FORMAT_R8G8B8A8_SRGB; }

 private:
  explicit Presenter(Context& context, VkSurfaceKHR surface) : context_(context), surface_(surface) {}
  Status init(uint32_t width, uint32_t height);
  Status create_swapchain(uint32_t width, uint32_t height);
  void destroy_swapchain_views();
  Status record_capture(VkCommandBuffer cmd, VkImage image);

  Context& context_;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  VkSurfaceFormatKHR format_{};
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkExtent2D extent_{0, 0};
  bool can_capture_ = false;  // the swapchain images can be a transfer source
  bool takes_copies_ = false;  // ... and destination (a still frame's layer is copied into them)
  std::vector<VkImage> images_;
  std::vector<VkImageView> views_;
  std::vector<VkFramebuffer> framebuffers_;
  std::vector<VkSemaphore> rendered_;  // per swapchain image: its commands are done, it may be presented
  VkSemaphore acquired_ = VK_NULL_HANDLE;
  VkRenderPass overlay_pass_ = VK_NULL_HANDLE;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer commands_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkBuffer capture_buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory capture_memory_ = VK_NULL_HANDLE;
  void* capture_mapped_ = nullptr;
  VkDeviceSize capture_capacity_ = 0;
};

}  // namespace fire::render
