#include "platform/render/present.hpp"

#include <algorithm>
#include <cstring>

#include "platform/render/barriers.hpp"

namespace fire::render {

namespace {

constexpr uint64_t kWaitNs = 60'000'000'000ull;  // a frame on lavapipe takes well under a second

bool is_bgra(VkFormat f) { return f == VK_FORMAT_B8G8R8A8_SRGB || f == VK_FORMAT_B8G8R8A8_UNORM; }

}  // namespace

Result<std::unique_ptr<Presenter>> Presenter::create(Context& context, VkSurfaceKHR surface, uint32_t width,
                                                     uint32_t height) {
  std::unique_ptr<Presenter> p(new Presenter(context, surface));
  if (Status s = p->init(width, height); !s) return Result<std::unique_ptr<Presenter>>::failure("Vulkan: " + s.error);
  return p;
}

Status Presenter::init(uint32_t width, uint32_t height) {
  VkDevice device = context_.device();
  VkBool32 supported = VK_FALSE;
  FIRE_VK_TRY(vkGetPhysicalDeviceSurfaceSupportKHR(context_.physical_device(), context_.queue_family(), surface_, &supported));
  if (!supported) return Status::failure("the device's queue cannot present to this window");

  uint32_t count = 0;
  FIRE_VK_TRY(vkGetPhysicalDeviceSurfaceFormatsKHR(context_.physical_device(), surface_, &count, nullptr));
  std::vector<VkSurfaceFormatKHR> formats(count);
  FIRE_VK_TRY(vkGetPhysicalDeviceSurfaceFormatsKHR(context_.physical_device(), surface_, &count, formats.data()));
  if (formats.empty()) return Status::failure("the window's surface offers no image format");
  // The renderer draws straight into the swapchain's images: an 8-bit sRGB format it can draw in.
  format_.format = VK_FORMAT_UNDEFINED;
  for (const VkSurfaceFormatKHR& f : formats)
    if ((f.format == VK_FORMAT_B8G8R8A8_SRGB || f.format == VK_FORMAT_R8G8B8A8_SRGB) &&
        f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) {
      format_ = f;
      break;
    }
  if (format_.format == VK_FORMAT_UNDEFINED)
    return Status::failure("the window's surface offers neither B8G8R8A8_SRGB nor R8G8B8A8_SRGB images");

  VkAttachmentDescription attachment{};
  attachment.format = format_.format;
  attachment.samples = VK_SAMPLE_COUNT_1_BIT;
  attachment.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;  // the scene the renderer drew
  attachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  attachment.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  attachment.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  attachment.initialLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  attachment.finalLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  VkAttachmentReference reference{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 1;
  subpass.pColorAttachments = &reference;
  VkSubpassDependency after_scene{};
  after_scene.srcSubpass = VK_SUBPASS_EXTERNAL;
  after_scene.dstSubpass = 0;
  after_scene.srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  after_scene.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  after_scene.dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  after_scene.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  VkRenderPassCreateInfo pass{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  pass.attachmentCount = 1;
  pass.pAttachments = &attachment;
  pass.subpassCount = 1;
  pass.pSubpasses = &subpass;
  pass.dependencyCount = 1;
  pass.pDependencies = &after_scene;
  FIRE_VK_TRY(vkCreateRenderPass(device, &pass, nullptr, &overlay_pass_));

  FIRE_TRY(context_.create_commands(pool_, commands_, fence_, true));
  VkSemaphoreCreateInfo semaphore{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  FIRE_VK_TRY(vkCreateSemaphore(device, &semaphore, nullptr, &acquired_));
  return create_swapchain(width, height);
}

Status Presenter::create_swapchain(uint32_t width, uint32_t height) {
  VkDevice device = context_.device();
  VkSurfaceCapabilitiesKHR caps;
  FIRE_VK_TRY(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(context_.physical_device(), surface_, &caps));
  VkExtent2D extent = caps.currentExtent;
  if (extent.width == UINT32_MAX) {  // the window system lets the swapchain choose
    extent.width = std::clamp(width, caps.minImageExtent.width, caps.maxImageExtent.width);
    extent.height = std::clamp(height, caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  destroy_swapchain_views();
  extent_ = extent;
  if (extent.width == 0 || extent.height == 0) return Status::success();  // minimised: no swapchain until restored
  can_capture_ = caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  takes_copies_ = caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT;

  uint32_t min_images = std::max(caps.minImageCount + 1, 2u);  // one to draw while one is shown
  if (caps.maxImageCount) min_images = std::min(min_images, caps.maxImageCount);
  VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  info.surface = surface_;
  info.minImageCount = min_images;
  info.imageFormat = format_.format;
  info.imageColorSpace = format_.colorSpace;
  info.imageExtent = extent;
  info.imageArrayLayers = 1;
  info.imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | (can_capture_ ? VK_IMAGE_USAGE_TRANSFER_SRC_BIT : 0) |
                    (takes_copies_ ? VK_IMAGE_USAGE_TRANSFER_DST_BIT : 0);
  info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  if (!(caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR))
    info.compositeAlpha = VK_COMPOSITE_ALPHA_INHERIT_BIT_KHR;
  info.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // vsync; the one mode every implementation offers
  info.clipped = VK_TRUE;
  info.oldSwapchain = swapchain_;
  VkSwapchainKHR created = VK_NULL_HANDLE;
  FIRE_VK_TRY(vkCreateSwapchainKHR(device, &info, nullptr, &created));
  if (swapchain_) vkDestroySwapchainKHR(device, swapchain_, nullptr);
  swapchain_ = created;

  uint32_t count = 0;
  FIRE_VK_TRY(vkGetSwapchainImagesKHR(device, swapchain_, &count, nullptr));
  images_.resize(count);
  FIRE_VK_TRY(vkGetSwapchainImagesKHR(device, swapchain_, &count, images_.data()));
  for (VkImage image : images_) {
    VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view.image = image;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format_.format;
    view.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    views_.push_back(VK_NULL_HANDLE);
    FIRE_VK_TRY(vkCreateImageView(device, &view, nullptr, &views_.back()));
    VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fb.renderPass = overlay_pass_;
    fb.attachmentCount = 1;
    fb.pAttachments = &views_.back();
    fb.width = extent.width;
    fb.height = extent.height;
    fb.layers = 1;
    framebuffers_.push_back(VK_NULL_HANDLE);
    FIRE_VK_TRY(vkCreateFramebuffer(device, &fb, nullptr, &framebuffers_.back()));
    VkSemaphoreCreateInfo semaphore{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    rendered_.push_back(VK_NULL_HANDLE);
    FIRE_VK_TRY(vkCreateSemaphore(device, &semaphore, nullptr, &rendered_.back()));
  }
  return Status::success();
}

void Presenter::destroy_swapchain_views() {
  VkDevice device = context_.device();
  for (VkFramebuffer f : framebuffers_) vkDestroyFramebuffer(device, f, nullptr);
  for (VkImageView v : views_) vkDestroyImageView(device, v, nullptr);
  for (VkSemaphore s : rendered_) vkDestroySemaphore(device, s, nullptr);
  framebuffers_.clear();
  views_.clear();
  rendered_.clear();
  images_.clear();
}

Status Presenter::resize(uint32_t width, uint32_t height) {
  FIRE_VK_TRY(vkDeviceWaitIdle(context_.device()));  // the old images and semaphores may still be in use
  return create_swapchain(width, height);
}

Presenter::~Presenter() {
  VkDevice device = context_.device();
  vkDeviceWaitIdle(device);  // nothing else to do on failure: everything is destroyed either way
  destroy_swapchain_views();
  if (swapchain_) vkDestroySwapchainKHR(device, swapchain_, nullptr);
  if (capture_buffer_) vkDestroyBuffer(device, capture_buffer_, nullptr);
  if (capture_memory_) vkFreeMemory(device, capture_memory_, nullptr);
  if (acquired_) vkDestroySemaphore(device, acquired_, nullptr);
  if (fence_) vkDestroyFence(device, fence_, nullptr);
  if (pool_) vkDestroyCommandPool(device, pool_, nullptr);
  if (overlay_pass_) vkDestroyRenderPass(device, overlay_pass_, nullptr);
  if (surface_) vkDestroySurfaceKHR(context_.instance(), surface_, nullptr);
}

Status Presenter::wait() {
  FIRE_VK_TRY(vkWaitForFences(context_.device(), 1, &fence_, VK_TRUE, kWaitNs));
  return Status::success();
}

Status Presenter::run_once(const std::function<void(VkCommandBuffer)>& record) {
  VkDevice device = context_.device();
  FIRE_TRY(wait());
  FIRE_VK_TRY(vkResetFences(device, 1, &fence_));
  FIRE_VK_TRY(vkResetCommandBuffer(commands_, 0));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  FIRE_VK_TRY(vkBeginCommandBuffer(commands_, &begin));
  record(commands_);
  FIRE_VK_TRY(vkEndCommandBuffer(commands_));
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &commands_;
  FIRE_VK_TRY(vkQueueSubmit(context_.queue(), 1, &submit, fence_));
  return wait();
}

Status Presenter::record_capture(VkCommandBuffer cmd, VkImage image) {
  VkDevice device = context_.device();
  const VkDeviceSize bytes = VkDeviceSize(extent_.width) * extent_.height * 4;
  if (bytes > capture_capacity_) {
    if (capture_buffer_) vkDestroyBuffer(device, capture_buffer_, nullptr);
    if (capture_memory_) vkFreeMemory(device, capture_memory_, nullptr);
    capture_buffer_ = VK_NULL_HANDLE;
    capture_memory_ = VK_NULL_HANDLE;
    capture_capacity_ = 0;
    FIRE_TRY(context_.create_mapped_buffer(bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, 0, capture_buffer_, capture_memory_,
                                           capture_mapped_));
    capture_capacity_ = bytes;
  }
  record_readback(cmd, image, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, extent_, capture_buffer_);
  record_barrier(cmd, image_barrier(image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                    VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_PIPELINE_STAGE_2_COPY_BIT, 0,
                                    VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0));
  return Status::success();
}

Result<Presented> Presenter::frame(Renderer& renderer, const Camera& camera, const DrawOptions& options,
                              const Overlay& overlay, Image* capture) {
  VkDevice device = context_.device();
  if (!swapchain_ || extent_.width == 0 || extent_.height == 0) return Presented::SwapchainStale;
  if (capture && !can_capture_) return Result<Presented>::failure("the window's images cannot be read back for a screenshot");
  if (renderer.color_format() != format_.format)
    return Result<Presented>::failure("the renderer draws in another format than the window's images (RenderSettings::color_format)");
  if (Status s = wait(); !s) return Result<Presented>::failure(s.error);
  if (renderer.width() != extent_.width || renderer.height() != extent_.height)
    if (Status s = renderer.resize(extent_.width, extent_.height); !s) return Result<Presented>::failure(s.error);

  uint32_t index = 0;
  const VkResult acquired = vkAcquireNextImageKHR(device, swapchain_, kWaitNs, acquired_, VK_NULL_HANDLE, &index);
  if (acquired == VK_ERROR_OUT_OF_DATE_KHR) return Presented::SwapchainStale;
  if (acquired != VK_SUCCESS && acquired != VK_SUBOPTIMAL_KHR)
    return Result<Presented>::failure(vk_failure("vkAcquireNextImageKHR", acquired));

  auto fail = [](const char* call, VkResult r) { return Result<Presented>::failure(vk_failure(call, r)); };
  if (VkResult r = vkResetFences(device, 1, &fence_); r != VK_SUCCESS) return fail("vkResetFences", r);
  VkCommandBuffer cmd = commands_;
  if (VkResult r = vkResetCommandBuffer(cmd, 0); r != VK_SUCCESS) return fail("vkResetCommandBuffer", r);
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  if (VkResult r = vkBeginCommandBuffer(cmd, &begin); r != VK_SUCCESS) return fail("vkBeginCommandBuffer", r);

  const VkImage image = images_[index];
  // Drawn straight into the swapchain image, or a still frame's layer copied into it: the acquire semaphore's
  // wait (at the submit, before colour output and copies) orders this after the presentation engine's read.
  renderer.record(cmd, camera, options, image, views_[index], takes_copies_);

  VkRenderPassBeginInfo pass{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  pass.renderPass = overlay_pass_;
  pass.framebuffer = framebuffers_[index];
  pass.renderArea = {{0, 0}, extent_};
  vkCmdBeginRenderPass(cmd, &pass, VK_SUBPASS_CONTENTS_INLINE);
  overlay(cmd);
  vkCmdEndRenderPass(cmd);
  if (capture)
    if (Status s = record_capture(cmd, image); !s) return Result<Presented>::failure(s.error);
  if (VkResult r = vkEndCommandBuffer(cmd); r != VK_SUCCESS) return fail("vkEndCommandBuffer", r);

  VkSemaphoreSubmitInfo wait_acquire{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  wait_acquire.semaphore = acquired_;
  wait_acquire.stageMask = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_2_COPY_BIT;
  VkSemaphoreSubmitInfo signal_rendered{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  signal_rendered.semaphore = rendered_[index];
  signal_rendered.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  VkCommandBufferSubmitInfo command{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  command.commandBuffer = cmd;
  VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  submit.waitSemaphoreInfoCount = 1;
  submit.pWaitSemaphoreInfos = &wait_acquire;
  submit.commandBufferInfoCount = 1;
  submit.pCommandBufferInfos = &command;
  submit.signalSemaphoreInfoCount = 1;
  submit.pSignalSemaphoreInfos = &signal_rendered;
  if (VkResult r = vkQueueSubmit2(context_.queue(), 1, &submit, fence_); r != VK_SUCCESS) return fail("vkQueueSubmit2", r);

  VkPresentInfoKHR present{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  present.waitSemaphoreCount = 1;
  present.pWaitSemaphores = &rendered_[index];
  present.swapchainCount = 1;
  present.pSwapchains = &swapchain_;
  present.pImageIndices = &index;
  const VkResult presented = vkQueuePresentKHR(context_.queue(), &present);
  if (presented != VK_SUCCESS && presented != VK_SUBOPTIMAL_KHR && presented != VK_ERROR_OUT_OF_DATE_KHR)
    return fail("vkQueuePresentKHR", presented);

  if (capture) {
    if (Status s = wait(); !s) return Result<Presented>::failure(s.error);
    capture->width = extent_.width;
    capture->height = extent_.height;
    const auto* bytes = static_cast<const uint8_t*>(capture_mapped_);
    capture->rgba.assign(bytes, bytes + size_t(extent_.width) * extent_.height * 4);
    if (is_bgra(format_.format))
      for (size_t i = 0; i < capture->rgba.size(); i += 4) std::swap(capture->rgba[i], capture->rgba[i + 2]);
    for (size_t i = 3; i < capture->rgba.size(); i += 4) capture->rgba[i] = 255;  // what the window shows is opaque
  }
  // Shown, but the swapchain no longer matches the window: the caller resizes before the next frame.
  return acquired == VK_SUCCESS && presented == VK_SUCCESS ? Presented::Shown : Presented::SwapchainStale;
}

}  // namespace fire::render
