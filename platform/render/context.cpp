#include "platform/render/context.hpp"

#include <cstdlib>
#include <cstring>
#include <iostream>

namespace fire::render {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr const char* kNoDevice =
    "no Vulkan device with Vulkan 1.3 and a graphics queue was found. On a machine without a GPU, install "
    "Mesa's CPU driver lavapipe: apt-get install mesa-vulkan-drivers";

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                     VkDebugUtilsMessageTypeFlagsEXT,
                                                     const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  std::string text = severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error: " : "warning: ";
  text += data && data->pMessage ? data->pMessage : "(no message)";
  static_cast<Context*>(user)->record_message(std::move(text));
  return VK_FALSE;
}

int device_rank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 4;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 3;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 1;
    default: return 0;
  }
}

bool has_layer(const char* name) {
  uint32_t count = 0;
  if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(count);
  if (vkEnumerateInstanceLayerProperties(&count, layers.data()) != VK_SUCCESS) return false;
  for (const auto& l : layers)
    if (std::strcmp(l.layerName, name) == 0) return true;
  return false;
}

}  // namespace

const char* vk_result_name(VkResult r) {
  switch (r) {
#define FIRE_VK_NAME(x) \
  case x: return #x;
    FIRE_VK_NAME(VK_SUCCESS)
    FIRE_VK_NAME(VK_NOT_READY)
    FIRE_VK_NAME(VK_TIMEOUT)
    FIRE_VK_NAME(VK_INCOMPLETE)
    FIRE_VK_NAME(VK_ERROR_OUT_OF_HOST_MEMORY)
    FIRE_VK_NAME(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    FIRE_VK_NAME(VK_ERROR_INITIALIZATION_FAILED)
    FIRE_VK_NAME(VK_ERROR_DEVICE_LOST)
    FIRE_VK_NAME(VK_ERROR_MEMORY_MAP_FAILED)
    FIRE_VK_NAME(VK_ERROR_LAYER_NOT_PRESENT)
    FIRE_VK_NAME(VK_ERROR_EXTENSION_NOT_PRESENT)
    FIRE_VK_NAME(VK_ERROR_FEATURE_NOT_PRESENT)
    FIRE_VK_NAME(VK_ERROR_INCOMPATIBLE_DRIVER)
    FIRE_VK_NAME(VK_ERROR_TOO_MANY_OBJECTS)
    FIRE_VK_NAME(VK_ERROR_FORMAT_NOT_SUPPORTED)
    FIRE_VK_NAME(VK_ERROR_FRAGMENTED_POOL)
    FIRE_VK_NAME(VK_ERROR_OUT_OF_POOL_MEMORY)
    FIRE_VK_NAME(VK_ERROR_SURFACE_LOST_KHR)
    FIRE_VK_NAME(VK_ERROR_OUT_OF_DATE_KHR)
    FIRE_VK_NAME(VK_SUBOPTIMAL_KHR)
#undef FIRE_VK_NAME
    default: return "VkResult (unnamed)";
  }
}

std::string vk_failure(const char* call, VkResult result) {
  std::string name(call);
  name = name.substr(0, name.find('('));
  return name + " failed: " + vk_result_name(result) + " (" + std::to_string(int(result)) + ")";
}

bool validation_default() {
  if (const char* env = std::getenv("FIRE_VK_VALIDATION"); env && *env) return std::strcmp(env, "0") != 0;
#ifdef NDEBUG
  return false;
#else
  return true;
#endif
}

Result<std::unique_ptr<Context>> Context::create(const ContextOptions& options) {
  std::unique_ptr<Context> c(new Context);
  if (Status s = c->init(options); !s) return Result<std::unique_ptr<Context>>::failure("Vulkan: " + s.error);
  return c;
}

Status Context::init(const ContextOptions& options) {
  uint32_t loader_version = VK_API_VERSION_1_0;
  FIRE_VK_TRY(vkEnumerateInstanceVersion(&loader_version));
  if (loader_version < VK_API_VERSION_1_3)
    return Status::failure("the Vulkan loader supports only Vulkan " + std::to_string(VK_API_VERSION_MAJOR(loader_version)) +
                           "." + std::to_string(VK_API_VERSION_MINOR(loader_version)) + "; 1.3 is required");
  if (options.validation && !has_layer(kValidationLayer))
    return Status::failure(std::string("validation was asked for but the layer ") + kValidationLayer +
                           " is missing (Debian package vulkan-validationlayers; FIRE_VK_VALIDATION=0 turns validation off)");

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "fire";
  app.pEngineName = "fire";
  app.apiVersion = VK_API_VERSION_1_3;
  VkDebugUtilsMessengerCreateInfoEXT messenger{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  messenger.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messenger.pfnUserCallback = on_validation_message;
  messenger.pUserData = this;
  const char* layers[] = {kValidationLayer};
  std::vector<const char*> extensions;
  for (const std::string& e : options.instance_extensions) extensions.push_back(e.c_str());
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  if (options.validation) {
    info.enabledLayerCount = 1;
    info.ppEnabledLayerNames = layers;
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    info.pNext = &messenger;  // also reports on instance creation and destruction
  }
  info.enabledExtensionCount = uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  const VkResult created = vkCreateInstance(&info, nullptr, &instance_);
  if (created == VK_ERROR_INCOMPATIBLE_DRIVER) return Status::failure(kNoDevice);
  if (created == VK_ERROR_EXTENSION_NOT_PRESENT && !options.instance_extensions.empty())
    return Status::failure("vkCreateInstance failed: the Vulkan loader lacks an instance extension the window needs "
                           "(VK_KHR_surface and the X11 or Wayland surface extension)");
  if (created != VK_SUCCESS) return Status::failure(vk_failure("vkCreateInstance", created));
  if (options.validation) {
    auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    if (!create_messenger) return Status::failure("vkCreateDebugUtilsMessengerEXT is not available");
    FIRE_VK_TRY(create_messenger(instance_, &messenger, nullptr, &messenger_));
  }
  FIRE_TRY(pick_device(options));

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue.queueFamilyIndex = queue_family_;
  queue.queueCount = 1;
  queue.pQueuePriorities = &priority;
  VkPhysicalDeviceVulkan13Features features13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  features13.dynamicRendering = VK_TRUE;
  features13.synchronization2 = VK_TRUE;
  VkPhysicalDeviceFeatures supported{};
  vkGetPhysicalDeviceFeatures(physical_, &supported);
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  features.pNext = &features13;
  features.features.fillModeNonSolid = supported.fillModeNonSolid;
  wireframe_ = supported.fillModeNonSolid;
  const char* swapchain[] = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
  VkDeviceCreateInfo device{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  device.pNext = &features;
  device.queueCreateInfoCount = 1;
  device.pQueueCreateInfos = &queue;
  if (options.can_present) {
    device.enabledExtensionCount = 1;
    device.ppEnabledExtensionNames = swapchain;
  }
  FIRE_VK_TRY(vkCreateDevice(physical_, &device, nullptr, &device_));
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
  return Status::success();
}

namespace {
bool has_device_extension(VkPhysicalDevice device, const char* name) {
  uint32_t count = 0;
  if (vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkExtensionProperties> extensions(count);
  if (vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data()) != VK_SUCCESS) return false;
  for (const auto& e : extensions)
    if (std::strcmp(e.extensionName, name) == 0) return true;
  return false;
}
}  // namespace

Status Context::create_commands(VkCommandPool& pool, VkCommandBuffer& buffer, VkFence& fence, bool signaled) const {
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool_info.queueFamilyIndex = queue_family_;
  FIRE_VK_TRY(vkCreateCommandPool(device_, &pool_info, nullptr, &pool));
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  FIRE_VK_TRY(vkAllocateCommandBuffers(device_, &alloc, &buffer));
  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  if (signaled) fence_info.flags = VK_FENCE_CREATE_SIGNALED_BIT;
  FIRE_VK_TRY(vkCreateFence(device_, &fence_info, nullptr, &fence));
  return Status::success();
}

Status Context::pick_device(const ContextOptions& options) {
  uint32_t count = 0;
  const VkResult listed = vkEnumeratePhysicalDevices(instance_, &count, nullptr);
  if (listed == VK_ERROR_INITIALIZATION_FAILED || (listed == VK_SUCCESS && count == 0)) return Status::failure(kNoDevice);
  if (listed != VK_SUCCESS) return Status::failure(vk_failure("vkEnumeratePhysicalDevices", listed));
  std::vector<VkPhysicalDevice> devices(count);
  FIRE_VK_TRY(vkEnumeratePhysicalDevices(instance_, &count, devices.data()));
  int best_rank = -1;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    if (p.apiVersion < VK_API_VERSION_1_3) continue;
    VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    VkPhysicalDeviceFeatures2 f{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    f.pNext = &f13;
    vkGetPhysicalDeviceFeatures2(d, &f);
    if (!f13.dynamicRendering || !f13.synchronization2) continue;
    if (options.can_present && !has_device_extension(d, VK_KHR_SWAPCHAIN_EXTENSION_NAME)) continue;
    uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(d, &families, nullptr);
    std::vector<VkQueueFamilyProperties> props(families);
    vkGetPhysicalDeviceQueueFamilyProperties(d, &families, props.data());
    for (uint32_t q = 0; q < families; ++q) {
      if (!(props[q].queueFlags & VK_QUEUE_GRAPHICS_BIT)) continue;
      if (options.can_present && !options.can_present(instance_, d, q)) continue;
      if (device_rank(p.deviceType) > best_rank) {
        best_rank = device_rank(p.deviceType);
        physical_ = d;
        queue_family_ = q;
        properties_ = p;
      }
      break;
    }
  }
  if (!physical_ && options.can_present)
    return Status::failure(std::string(kNoDevice) + " (a device was needed whose queue can present to the window, "
                           "with VK_KHR_swapchain)");
  if (!physical_) return Status::failure(kNoDevice);
  vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);
  return Status::success();
}

Context::~Context() {
  if (device_) {
    vkDeviceWaitIdle(device_);  // nothing to do on failure: the device is destroyed either way
    vkDestroyDevice(device_, nullptr);
  }
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
}

Result<uint32_t> Context::memory_type(uint32_t type_bits, VkMemoryPropertyFlags flags) const {
  for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
    if ((type_bits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & flags) == flags) return i;
  return Result<uint32_t>::failure("no Vulkan memory type with the needed properties");
}

Status Context::allocate(const VkMemoryRequirements& req, VkMemoryPropertyFlags preferred,
                         VkMemoryPropertyFlags fallback, VkDeviceMemory& memory) const {
  auto type = memory_type(req.memoryTypeBits, preferred);
  if (!type) type = memory_type(req.memoryTypeBits, fallback);
  if (!type) return Status::failure(type.error());
  VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  info.allocationSize = req.size;
  info.memoryTypeIndex = *type;
  FIRE_VK_TRY(vkAllocateMemory(device_, &info, nullptr, &memory));
  return Status::success();
}

Status Context::create_mapped_buffer(VkDeviceSize bytes, VkBufferUsageFlags usage, VkMemoryPropertyFlags extra,
                                     VkBuffer& buffer, VkDeviceMemory& memory, void*& mapped) const {
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = bytes;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  FIRE_VK_TRY(vkCreateBuffer(device_, &info, nullptr, &buffer));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, buffer, &req);
  constexpr VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  FIRE_TRY(allocate(req, host | extra, host, memory));
  FIRE_VK_TRY(vkBindBufferMemory(device_, buffer, memory, 0));
  FIRE_VK_TRY(vkMapMemory(device_, memory, 0, VK_WHOLE_SIZE, 0, &mapped));
  return Status::success();
}

void Context::record_message(std::string message) {
  std::cerr << "vulkan validation " << message << "\n";
  std::lock_guard<std::mutex> lock(messages_mutex_);
  messages_.push_back(std::move(message));
}

size_t Context::validation_message_count() const {
  std::lock_guard<std::mutex> lock(messages_mutex_);
  return messages_.size();
}

std::vector<std::string> Context::validation_messages() const {
  std::lock_guard<std::mutex> lock(messages_mutex_);
  return messages_;
}

}  // namespace fire::render
