#pragma once
// The image barriers and readbacks that the offscreen and present paths record (synchronization2).
#include <vulkan/vulkan.h>

#include <span>

namespace fire::render {

// A layout transition of one image's first mip and layer, on one queue family.
VkImageMemoryBarrier2 image_barrier(VkImage image, VkImageAspectFlags aspect, VkImageLayout from, VkImageLayout to,
                                    VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                                    VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access);

// One pipeline barrier of just `barrier`, or of all of `barriers`.
void record_barrier(VkCommandBuffer cmd, const VkImageMemoryBarrier2& barrier);
void record_barriers(VkCommandBuffer cmd, std::span<const VkImageMemoryBarrier2> barriers);

// A copy of a colour image that was last written as a colour attachment and now is in `layout`, all of
// `extent`, into `buffer` (4 bytes a pixel, rows packed), which the host may read once the submission's fence
// has signalled. The image is left in TRANSFER_SRC_OPTIMAL.
void record_readback(VkCommandBuffer cmd, VkImage image, VkImageLayout layout, VkExtent2D extent, VkBuffer buffer);

}  // namespace fire::render
