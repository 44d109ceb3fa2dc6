#pragma once
// The Vulkan instance and device the renderer draws with.
//
// Device choice prefers a real GPU (discrete, then integrated, then virtual) and falls back to a CPU
// device such as lavapipe (Mesa's software driver, Debian package `mesa-vulkan-drivers`), so the renderer
// runs on machines without a GPU. Vulkan 1.3 is required (dynamic rendering, synchronization2).
//
// Validation: with ContextOptions::validation the Khronos validation layer is enabled and a debug-utils
// messenger counts every warning and error (printed to stderr as they come); tests fail on any. The
// default is on in debug builds and otherwise off; FIRE_VK_VALIDATION=1 or =0 overrides it.
//
// Every VkResult is checked in every build; setup failures come back as Result/Status whose message
// names the call that failed.
#include <vulkan/vulkan.h>

#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "engine/common.hpp"

namespace fire::render {

// "vkCreateDevice failed: VK_ERROR_OUT_OF_HOST_MEMORY" for the call text `call` (arguments dropped).
std::string vk_failure(const char* call, VkResult result);
const char* vk_result_name(VkResult result);

// Evaluates a Vulkan call; on anything but VK_SUCCESS returns a failed Status naming it.
#define FIRE_VK_TRY(call)                                                            \
  do {                                                                               \
    const VkResult fire_vk_result_ = (call);                                         \
    if (fire_vk_result_ != VK_SUCCESS)                                               \
      return ::fire::Status::failure(::fire::render::vk_failure(#call, fire_vk_result_)); \
  } while (0)

// Like FIRE_VK_TRY inside a function that returns a Status, for another Status.
#define FIRE_TRY(status_expr)                        \
  do {                                               \
    ::fire::Status fire_status_ = (status_expr);     \
    if (!fire_status_) return fire_status_;          \
  } while (0)

bool validation_default();

struct ContextOptions {
  bool validation = validation_default();
  // For a window: the instance extensions its surface needs (from GLFW), and a test of whether a queue
  // family of a device can present to it; with it set, VK_KHR_swapchain is required of the device too.
  std::vector<std::string> instance_extensions;
  std::function<bool(VkInstance, VkPhysicalDevice, uint32_t family)> can_present;
};

class Context {
 public:
  static Result<std::unique_ptr<Context>> create(const ContextOptions& options = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physical_device() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queue_family() const { return queue_family_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  std::string device_name() const { return properties_.deviceName; }
  bool is_cpu_device() const { return properties_.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU; }
  bool validation() const { return messenger_ != VK_NULL_HANDLE; }
  // A pool whose buffers can be reset, one primary command buffer from it, and a fence (already signalled
  // when `signaled`, for a first wait with no frame in flight): what the offscreen and present paths record with.
  Status create_commands(VkCommandPool& pool, VkCommandBuffer& buffer, VkFence& fence, bool signaled) const;
  // Whether polygons can be drawn as lines (the renderer's wireframe).
  bool wireframe_supported() const { return wireframe_; }

  // A memory type among `type_bits` with all of `flags`.
  Result<uint32_t> memory_type(uint32_t type_bits, VkMemoryPropertyFlags flags) const;
  // Memory for `req` of a type with all of `preferred`, else of one with all of `fallback`.
  Status allocate(const VkMemoryRequirements& req, VkMemoryPropertyFlags preferred, VkMemoryPropertyFlags fallback,
                  VkDeviceMemory& memory) const;
  // An exclusive buffer of `bytes` in host-visible, coherent memory (of a type with all of `extra` too where
  // there is one), mapped whole until its memory is freed. What was made before a failure is in the outputs.
  Status create_mapped_buffer(VkDeviceSize bytes, VkBufferUsageFlags usage, VkMemoryPropertyFlags extra,
                              VkBuffer& buffer, VkDeviceMemory& memory, void*& mapped) const;

  // Validation warnings and errors reported so far (0 when validation is off).
  size_t validation_message_count() const;
  std::vector<std::string> validation_messages() const;
  // Called by the messenger; public only for its C callback.
  void record_message(std::string message);

 private:
  Context() = default;
  Status init(const ContextOptions& options);
  Status pick_device(const ContextOptions& options);

  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  VkPhysicalDeviceProperties properties_{};
  bool wireframe_ = false;
  VkPhysicalDeviceMemoryProperties memory_{};
  mutable std::mutex messages_mutex_;  // the layer may report from any thread that calls Vulkan
  std::vector<std::string> messages_;
};

}  // namespace fire::render
