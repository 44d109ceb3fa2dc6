#include "platform/render/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <string>
#include <tuple>
#include <unordered_map>

#include "platform/render/barriers.hpp"

// SPIR-V compiled from shaders/ at build time (platform/render/CMakeLists.txt).
#include "shaders/curve_vert.h"
#include "shaders/flat_frag.h"
#include "shaders/marker_frag.h"
#include "shaders/marker_vert.h"
#include "shaders/surface_frag.h"
#include "shaders/surface_vert.h"
#include "shaders/wireframe_frag.h"

namespace fire::render {

namespace {

// The push constants of shaders/common.glsl.
struct PushConstants {
  glm::mat4 view_proj;
  glm::vec4 eye;
  glm::vec4 color;
  glm::vec4 params;
  glm::vec4 light;
};
static_assert(sizeof(PushConstants) == 128, "the minimum maxPushConstantsSize");

constexpr uint64_t kFenceTimeoutNs = 60'000'000'000ull;  // a frame on lavapipe takes well under a second

float srgb_to_linear(uint8_t c) {
  float v = float(c) / 255.0f;
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}
glm::vec4 linear(const uint8_t (&c)[3], float alpha = 1.0f) {
  return {srgb_to_linear(c[0]), srgb_to_linear(c[1]), srgb_to_linear(c[2]), alpha};
}
glm::vec3 to_float(const Vec3& p) { return {float(p.x()), float(p.y()), float(p.z())}; }

constexpr VkBufferUsageFlags kVertex = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT;
constexpr VkBufferUsageFlags kIndex = VK_BUFFER_USAGE_INDEX_BUFFER_BIT;

struct PipelineDesc {
  std::span<const uint32_t> vert, frag;
  std::vector<VkVertexInputBindingDescription> bindings;
  std::vector<VkVertexInputAttributeDescription> attributes;
  bool depth_test = true, depth_write = true, blend = false;
  bool lines = false;  // polygons as lines, pulled towards the viewer by a depth bias (the wireframe)
};

}  // namespace

Result<std::unique_ptr<Renderer>> Renderer::create(Context& context, const RenderSettings& settings) {
  if (settings.width == 0 || settings.height == 0 || settings.width > 8192 || settings.height > 8192)
    return Result<std::unique_ptr<Renderer>>::failure("image size must be 1 to 8192 pixels a side");
  RenderSettings chosen = settings;
  if (chosen.samples == 0) {
    if (const char* env = std::getenv("FIRE_SAMPLES"); env && *env) {
      const std::string value = env;
      if (value != "1" && value != "2" && value != "4" && value != "8")
        return Result<std::unique_ptr<Renderer>>::failure("FIRE_SAMPLES must be 1, 2, 4 or 8, not '" + value + "'");
      chosen.samples = uint32_t(std::stoul(value));
    } else {
      chosen.samples = context.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU ? 1 : 4;
    }
  }
  if (chosen.samples != 1 && chosen.samples != 2 && chosen.samples != 4 && chosen.samples != 8)
    return Result<std::unique_ptr<Renderer>>::failure("samples per pixel must be 0 (by device), 1, 2, 4 or 8");
  if (chosen.color_format != VK_FORMAT_R8G8B8A8_SRGB && chosen.color_format != VK_FORMAT_B8G8R8A8_SRGB)
    return Result<std::unique_ptr<Renderer>>::failure("the colour format must be R8G8B8A8_SRGB or B8G8R8A8_SRGB");
  std::unique_ptr<Renderer> r(new Renderer(context, chosen));
  if (Status s = r->init(); !s) return Result<std::unique_ptr<Renderer>>::failure("Vulkan: " + s.error);
  return r;
}

Status Renderer::init() {
  const VkPhysicalDeviceLimits& limits = context_.properties().limits;
  const VkSampleCountFlags supported = limits.framebufferColorSampleCounts & limits.framebufferDepthSampleCounts;
  for (VkSampleCountFlagBits n : {VK_SAMPLE_COUNT_8_BIT, VK_SAMPLE_COUNT_4_BIT, VK_SAMPLE_COUNT_2_BIT})
    if (uint32_t(n) <= settings_.samples && (supported & n)) {
      samples_ = n;
      break;
    }
  VkFormatProperties depth_props;
  vkGetPhysicalDeviceFormatProperties(context_.physical_device(), depth_format_, &depth_props);
  if (!(depth_props.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT))
    depth_format_ = VK_FORMAT_X8_D24_UNORM_PACK32;  // one of the two is always supported

  FIRE_TRY(create_targets());

  FIRE_TRY(context_.create_commands(pool_, commands_, fence_, false));
  return create_pipelines();
}

Status Renderer::create_targets() {
  // The frame's targets take the still frame's layer by copy (record()).
  constexpr VkImageUsageFlags color = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, depth = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
  constexpr VkImageUsageFlags from = VK_IMAGE_USAGE_TRANSFER_SRC_BIT, into = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  if (samples_ != VK_SAMPLE_COUNT_1_BIT) FIRE_TRY(create_target(color_, color_format_, color | into, samples_, VK_IMAGE_ASPECT_COLOR_BIT));
  FIRE_TRY(create_target(resolve_, color_format_, color | from | into, VK_SAMPLE_COUNT_1_BIT, VK_IMAGE_ASPECT_COLOR_BIT));
  FIRE_TRY(create_target(depth_, depth_format_, depth | into, samples_, VK_IMAGE_ASPECT_DEPTH_BIT));
  FIRE_TRY(create_target(layer_color_, color_format_, color | from, samples_, VK_IMAGE_ASPECT_COLOR_BIT));
  FIRE_TRY(create_target(layer_depth_, depth_format_, depth | from, samples_, VK_IMAGE_ASPECT_DEPTH_BIT));
  last_key_.reset();
  layer_ready_ = false;
  bool grown = false;
  return reserve(readback_, VkDeviceSize(settings_.width) * settings_.height * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, grown);
}

Status Renderer::resize(uint32_t width, uint32_t height) {
  if (width == 0 || height == 0 || width > 8192 || height > 8192)
    return Status::failure("image size must be 1 to 8192 pixels a side");
  FIRE_VK_TRY(vkDeviceWaitIdle(context_.device()));  // the old targets may still be in use
  for (Target* t : {&color_, &resolve_, &depth_, &layer_color_, &layer_depth_}) destroy(*t);
  destroy(readback_);
  settings_.width = width;
  settings_.height = height;
  return create_targets();
}

Status Renderer::create_target(Target& target, VkFormat format, VkImageUsageFlags usage, VkSampleCountFlagBits samples,
                               VkImageAspectFlags aspect) {
  VkDevice device = context_.device();
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {settings_.width, settings_.height, 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = samples;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  FIRE_VK_TRY(vkCreateImage(device, &info, nullptr, &target.image));
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device, target.image, &req);
  FIRE_TRY(context_.allocate(req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0, target.memory));
  FIRE_VK_TRY(vkBindImageMemory(device, target.image, target.memory, 0));
  VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  view.image = target.image;
  view.viewType = VK_IMAGE_VIEW_TYPE_2D;
  view.format = format;
  view.subresourceRange = {aspect, 0, 1, 0, 1};
  FIRE_VK_TRY(vkCreateImageView(device, &view, nullptr, &target.view));
  return Status::success();
}

Status Renderer::reserve(Buffer& buffer, VkDeviceSize bytes, VkBufferUsageFlags usage, bool& grown) {
  grown = false;
  bytes = std::max<VkDeviceSize>(bytes, 256);
  if (buffer.capacity >= bytes) return Status::success();
  grown = true;
  const VkDeviceSize capacity = std::max(bytes, buffer.capacity * 2);
  // The GPU reads buffers only inside draw(), which waits for its frame to finish.
  destroy(buffer);
  // Readback is read by the CPU: cached memory where there is such.
  const VkMemoryPropertyFlags extra =
      usage == VK_BUFFER_USAGE_TRANSFER_DST_BIT ? VK_MEMORY_PROPERTY_HOST_CACHED_BIT : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
  FIRE_TRY(context_.create_mapped_buffer(capacity, usage, extra, buffer.buffer, buffer.memory, buffer.mapped));
  buffer.capacity = capacity;
  return Status::success();
}

void Renderer::destroy(Buffer& buffer) {
  VkDevice device = context_.device();
  if (buffer.buffer) vkDestroyBuffer(device, buffer.buffer, nullptr);
  if (buffer.memory) vkFreeMemory(device, buffer.memory, nullptr);  // unmaps implicitly
  buffer = Buffer{};
}

void Renderer::destroy(Target& target) {
  VkDevice device = context_.device();
  if (target.view) vkDestroyImageView(device, target.view, nullptr);
  if (target.image) vkDestroyImage(device, target.image, nullptr);
  if (target.memory) vkFreeMemory(device, target.memory, nullptr);
  target = Target{};
}

Renderer::~Renderer() {
  VkDevice device = context_.device();
  vkDeviceWaitIdle(device);  // nothing else to do on failure: everything is destroyed either way
  for (Buffer* b : {&readback_, &points_, &vertices_, &surface_vertices_, &surface_indices_, &reference_vertices_,
                    &reference_indices_, &stroke_, &pen_, &marks_})
    destroy(*b);
  for (Coarse& c : coarse_) destroy(c.indices);
  for (Target* t : {&color_, &resolve_, &depth_, &layer_color_, &layer_depth_}) destroy(*t);
  for (VkPipeline p : {surface_, reference_pipeline_, curves_, markers_, wireframe_, pen_face_})
    if (p) vkDestroyPipeline(device, p, nullptr);
  if (layout_) vkDestroyPipelineLayout(device, layout_, nullptr);
  if (fence_) vkDestroyFence(device, fence_, nullptr);
  if (pool_) vkDestroyCommandPool(device, pool_, nullptr);
}

Status Renderer::create_pipelines() {
  VkDevice device = context_.device();
  VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(PushConstants)};
  VkPipelineLayoutCreateInfo layout{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout.pushConstantRangeCount = 1;
  layout.pPushConstantRanges = &range;
  FIRE_VK_TRY(vkCreatePipelineLayout(device, &layout, nullptr, &layout_));

  auto build = [&](const PipelineDesc& d, VkPipeline& out) -> Status {
    VkShaderModule modules[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
    std::span<const uint32_t> code[2] = {d.vert, d.frag};
    Status status;
    for (int i = 0; i < 2 && status; ++i) {
      VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
      info.codeSize = code[i].size_bytes();
      info.pCode = code[i].data();
      const VkResult r = vkCreateShaderModule(device, &info, nullptr, &modules[i]);
      if (r != VK_SUCCESS) status = Status::failure(vk_failure("vkCreateShaderModule", r));
    }
    if (status) {
      VkPipelineShaderStageCreateInfo stages[2]{};
      for (int i = 0; i < 2; ++i) {
        stages[i].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        stages[i].stage = i == 0 ? VK_SHADER_STAGE_VERTEX_BIT : VK_SHADER_STAGE_FRAGMENT_BIT;
        stages[i].module = modules[i];
        stages[i].pName = "main";
      }
      VkPipelineVertexInputStateCreateInfo input{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
      input.vertexBindingDescriptionCount = uint32_t(d.bindings.size());
      input.pVertexBindingDescriptions = d.bindings.data();
      input.vertexAttributeDescriptionCount = uint32_t(d.attributes.size());
      input.pVertexAttributeDescriptions = d.attributes.data();
      VkPipelineInputAssemblyStateCreateInfo assembly{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
      assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
      VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
      viewport.viewportCount = 1;
      viewport.scissorCount = 1;
      VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
      raster.polygonMode = d.lines ? VK_POLYGON_MODE_LINE : VK_POLYGON_MODE_FILL;
      raster.depthBiasEnable = d.lines;
      raster.depthBiasConstantFactor = d.lines ? -4.0f : 0.0f;
      raster.depthBiasSlopeFactor = d.lines ? -1.0f : 0.0f;
      raster.cullMode = VK_CULL_MODE_NONE;  // open surfaces are seen from both sides
      raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
      raster.lineWidth = 1.0f;
      VkPipelineMultisampleStateCreateInfo multisample{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
      multisample.rasterizationSamples = samples_;
      VkPipelineDepthStencilStateCreateInfo depth{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
      depth.depthTestEnable = d.depth_test;
      depth.depthWriteEnable = d.depth_write;
      depth.depthCompareOp = VK_COMPARE_OP_LESS_OR_EQUAL;
      VkPipelineColorBlendAttachmentState blend{};
      blend.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT |
                             VK_COLOR_COMPONENT_A_BIT;
      if (d.blend) {
        blend.blendEnable = VK_TRUE;
        blend.srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA;
        blend.dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
        blend.colorBlendOp = VK_BLEND_OP_ADD;
        blend.srcAlphaBlendFactor = VK_BLEND_FACTOR_ZERO;
        blend.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
        blend.alphaBlendOp = VK_BLEND_OP_ADD;
      }
      VkPipelineColorBlendStateCreateInfo blending{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
      blending.attachmentCount = 1;
      blending.pAttachments = &blend;
      VkDynamicState dynamic_states[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
      VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
      dynamic.dynamicStateCount = 2;
      dynamic.pDynamicStates = dynamic_states;
      VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
      rendering.colorAttachmentCount = 1;
      rendering.pColorAttachmentFormats = &color_format_;
      rendering.depthAttachmentFormat = depth_format_;
      VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
      info.pNext = &rendering;
      info.stageCount = 2;
      info.pStages = stages;
      info.pVertexInputState = &input;
      info.pInputAssemblyState = &assembly;
      info.pViewportState = &viewport;
      info.pRasterizationState = &raster;
      info.pMultisampleState = &multisample;
      info.pDepthStencilState = &depth;
      info.pColorBlendState = &blending;
      info.pDynamicState = &dynamic;
      info.layout = layout_;
      const VkResult r = vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &out);
      if (r != VK_SUCCESS) status = Status::failure(vk_failure("vkCreateGraphicsPipelines", r));
    }
    for (VkShaderModule m : modules)
      if (m) vkDestroyShaderModule(device, m, nullptr);
    return status;
  };

  const auto instance = VK_VERTEX_INPUT_RATE_INSTANCE;
  PipelineDesc surface{surface_vert, surface_frag, {{0, 24, VK_VERTEX_INPUT_RATE_VERTEX}},
                       {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0}, {1, 0, VK_FORMAT_R32G32B32_SFLOAT, 12}}};
  PipelineDesc reference = surface;
  reference.depth_write = false;
  reference.blend = true;
  // The face under the pen shows through whatever is in front of it: the pen is over it, so it faces the view.
  PipelineDesc pen_face = reference;
  pen_face.depth_test = false;
  // A segment is two consecutive points: one binding read per instance at offsets 0 and 12.
  PipelineDesc curves{curve_vert, flat_frag, {{0, 12, instance}},
                      {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0}, {1, 0, VK_FORMAT_R32G32B32_SFLOAT, 12}}};
  PipelineDesc markers{marker_vert, marker_frag, {{0, 12, instance}}, {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0}}};
  FIRE_TRY(build(surface, surface_));
  FIRE_TRY(build(reference, reference_pipeline_));
  FIRE_TRY(build(pen_face, pen_face_));
  FIRE_TRY(build(curves, curves_));
  if (context_.wireframe_supported()) {
    PipelineDesc wireframe = surface;
    wireframe.frag = wireframe_frag;
    wireframe.lines = true;
    FIRE_TRY(build(wireframe, wireframe_));
  }
  return build(markers, markers_);
}

void Renderer::copy_into(Buffer& buffer, VkDeviceSize offset, const void* data, VkDeviceSize bytes) {
  std::memcpy(static_cast<char*>(buffer.mapped) + offset, data, bytes);
  stats_.bytes += bytes;
}

Status Renderer::upload(const Mesh& network, const SurfaceLevels& surface) {
  stats_ = {};
  // What the still frame's layer draws from, besides the buffers' bytes.
  const auto drawn = std::tuple(curve_draws_, pending_draws_, marker_draws_, surface_draws_, surface_settled_);
  FIRE_TRY(upload_points(network));
  FIRE_TRY(upload_vertices(network));
  network_frame_ = network.frame();
  FIRE_TRY(upload_surface(surface));
  if (stats_.bytes || drawn != std::tuple(curve_draws_, pending_draws_, marker_draws_, surface_draws_, surface_settled_))
    ++scene_version_;
  return Status::success();
}

Status Renderer::upload_points(const Mesh& network) {
  bool grown = false;
  FIRE_TRY(reserve(points_, VkDeviceSize(network.points.size()) * sizeof(glm::vec3), kVertex, grown));
  if (grown) edge_records_.clear();
  edge_records_.resize(network.edge_slots());
  curve_draws_.clear();
  pending_draws_.clear();
  std::vector<glm::vec3> floats;
  for (EdgeIndex e{0}; e < network.edge_slots(); ++e) {
    EdgeRecord& record = edge_records_[e];
    if (!network.edge_alive(e)) {
      record = {};
      continue;
    }
    const EdgeRecord now{network.edges.generation[e], network.edges.point_offset[e], network.edges.point_count[e]};
    const bool stamped = network.edges.changes.changed_since(e, network_frame_);
    if (stamped || now.generation != record.generation || now.offset != record.offset || now.count != record.count) {
      floats.clear();
      for (const Vec3& p : network.polyline(e)) floats.push_back(to_float(p));
      copy_into(points_, VkDeviceSize(now.offset) * sizeof(glm::vec3), floats.data(), floats.size() * sizeof(glm::vec3));
      ++stats_.edges;
      record = now;
    }
    if (now.count >= 2) (network.is_pending(e) ? pending_draws_ : curve_draws_).emplace_back(now.offset, now.count);
  }
  return Status::success();
}

Status Renderer::upload_vertices(const Mesh& network) {
  const uint32_t slots = uint32_t(network.vertex_slots());
  bool grown = false;
  FIRE_TRY(reserve(vertices_, VkDeviceSize(slots) * sizeof(glm::vec3), kVertex, grown));
  if (grown) vertex_live_.clear();
  vertex_copy_.resize(slots);
  vertex_live_.resize(slots, 0);
  marker_draws_.clear();
  for (VertexIndex v{0}; v < slots; ++v) {
    if (!network.vertex_alive(v)) {
      vertex_live_[v] = 0;
      continue;
    }
    const glm::vec3 p = to_float(network.vertices.position[v]);
    if (!vertex_live_[v] || vertex_copy_[v] != p) {
      vertex_copy_[v] = p;
      vertex_live_[v] = 1;
      copy_into(vertices_, VkDeviceSize(v) * sizeof(glm::vec3), &p, sizeof p);
      ++stats_.vertices;
    }
    if (!marker_draws_.empty() && marker_draws_.back().first + marker_draws_.back().second == v)
      ++marker_draws_.back().second;
    else
      marker_draws_.emplace_back(v, 1);
  }
  return Status::success();
}

Status Renderer::upload_surface(const SurfaceLevels& s) {
  surface_settled_ = s.settled;
  surface_level_ = s.level;
  if (s.empty()) {
    ++surface_layout_;
    blocks_.clear();
    free_blocks_.clear();
    surface_draws_.clear();
    surface_vertex_end_ = surface_quad_end_ = 0;
    surface_seen_ = false;  // whatever comes next is laid out afresh
    return Status::success();
  }
  if (!surface_seen_ || s.topology_version != surface_topology_) {
    FIRE_TRY(layout_surface(s));
  } else if (s.frame != surface_frame_) {
    write_surface_vertices(s, s.changed);
  }
  surface_seen_ = true;
  surface_topology_ = s.topology_version;
  surface_frame_ = s.frame;
  return Status::success();
}

Status Renderer::layout_surface(const SurfaceLevels& s) {
  // The blocks held so far, by key; a key seen twice (never from the subdivide system) keeps its first.
  ++surface_layout_;
  surface_quads_ = s.quad_count();
  Box box;
  for (const Vec3& p : s.positions) box.add(p);
  surface_centre_ = 0.5f * (box.lo + box.hi);
  surface_radius_ = 0.5f * glm::length(box.hi - box.lo);
  std::vector<Block> old = std::move(blocks_);
  std::unordered_map<uint32_t, size_t> old_by_key;
  for (size_t i = 0; i < old.size(); ++i) old_by_key.emplace(old[i].key, i);
  std::vector<uint8_t> old_kept(old.size(), 0);
  blocks_.clear();
  block_vertex_.assign(s.vertex_count(), kNone);
  for (uint32_t p = 0; p < s.patch_count(); ++p) {
    Block b;
    b.key = s.patch_key(p);
    for (size_t i = 4 * size_t(s.patch_begin(p)); i < 4 * size_t(s.patch_end(p)); ++i) {
      uint32_t& local = block_vertex_[s.quads[i]];
      if (local == kNone) {
        local = uint32_t(b.vertices.size());
        b.vertices.push_back(s.quads[i]);
      }
      b.quads.push_back(local);
    }
    for (uint32_t v : b.vertices) block_vertex_[v] = kNone;
    b.vertex_count = uint32_t(b.vertices.size());
    b.quad_count = uint32_t(b.quads.size() / 4);
    b.first_quad = kNone;  // to be placed
    if (auto it = old_by_key.find(b.key); it != old_by_key.end() && !old_kept[it->second] && old[it->second].quads == b.quads) {
      b.first_vertex = old[it->second].first_vertex;
      b.first_quad = old[it->second].first_quad;
      old_kept[it->second] = 1;
    }
    blocks_.push_back(std::move(b));
  }
  for (size_t i = 0; i < old.size(); ++i)
    if (!old_kept[i]) free_blocks_.push_back({kNone, old[i].first_vertex, old[i].vertex_count, old[i].first_quad, old[i].quad_count, {}, {}});

  // Laid out afresh once the freed quads outnumber the used ones: the buffers stay within about twice the
  // surface, for one whole upload now and then.
  uint64_t used = 0, freed = 0;
  for (const Block& b : blocks_) used += b.quad_count;
  for (const Block& f : free_blocks_) freed += f.quad_count;
  if (freed > used) {
    free_blocks_.clear();
    surface_vertex_end_ = surface_quad_end_ = 0;
    for (Block& b : blocks_) b.first_quad = kNone;
  }
  std::vector<uint8_t> placed(blocks_.size(), 0);  // blocks whose triangles must be copied
  for (size_t k = 0; k < blocks_.size(); ++k) {
    Block& b = blocks_[k];
    if (b.first_quad != kNone) continue;
    placed[k] = 1;
    size_t best = free_blocks_.size();  // the smallest freed block that holds it
    for (size_t i = 0; i < free_blocks_.size(); ++i) {
      const Block& f = free_blocks_[i];
      if (f.vertex_count >= b.vertex_count && f.quad_count >= b.quad_count &&
          (best == free_blocks_.size() || f.quad_count < free_blocks_[best].quad_count))
        best = i;
    }
    if (best < free_blocks_.size()) {
      Block& f = free_blocks_[best];
      b.first_vertex = f.first_vertex;
      b.first_quad = f.first_quad;
      f.first_vertex += b.vertex_count;
      f.vertex_count -= b.vertex_count;
      f.first_quad += b.quad_count;
      f.quad_count -= b.quad_count;
      if (f.vertex_count == 0 || f.quad_count == 0) free_blocks_.erase(free_blocks_.begin() + ptrdiff_t(best));
    } else {
      b.first_vertex = surface_vertex_end_;
      b.first_quad = surface_quad_end_;
      surface_vertex_end_ += b.vertex_count;
      surface_quad_end_ += b.quad_count;
    }
  }
  // Space never written holds NaN in the copy, so that every vertex placed there differs from it.
  surface_vertex_copy_.resize(2 * size_t(surface_vertex_end_), glm::vec3(std::nanf("")));
  surface_index_copy_.resize(6 * size_t(surface_quad_end_));
  FIRE_TRY(reserve_surface(placed));

  for (size_t k = 0; k < blocks_.size(); ++k) {
    if (!placed[k]) continue;
    const Block& b = blocks_[k];
    uint32_t* out = &surface_index_copy_[6 * size_t(b.first_quad)];
    for (size_t q = 0; q < b.quad_count; ++q) {
      const uint32_t* c = &b.quads[4 * q];
      const uint32_t o = b.first_vertex;
      for (uint32_t corner : {c[0], c[1], c[2], c[0], c[2], c[3]}) *out++ = o + corner;
    }
    copy_into(surface_indices_, VkDeviceSize(b.first_quad) * 24, &surface_index_copy_[6 * size_t(b.first_quad)],
              VkDeviceSize(b.quad_count) * 24);
    stats_.surface_quads += b.quad_count;
  }
  write_surface_vertices(s, {0, s.vertex_count()});

  std::vector<std::pair<uint32_t, uint32_t>> ranges;  // (first quad, quads) per block, then in buffer order
  for (const Block& b : blocks_) ranges.emplace_back(b.first_quad, b.quad_count);
  std::sort(ranges.begin(), ranges.end());
  surface_draws_.clear();
  for (const auto& [first, count] : ranges) {
    if (!surface_draws_.empty() && surface_draws_.back().first + surface_draws_.back().second == 6 * first)
      surface_draws_.back().second += 6 * count;
    else
      surface_draws_.emplace_back(6 * first, 6 * count);
  }
  return Status::success();
}

Status Renderer::reserve_surface(std::vector<uint8_t>& placed) {
  // Half again what is needed when growing, so that appended blocks reallocate now and then only.
  auto room = [](VkDeviceSize need, const Buffer& b) { return need <= b.capacity ? need : need + need / 2; };
  bool grown = false;
  FIRE_TRY(reserve(surface_vertices_, room(VkDeviceSize(surface_vertex_end_) * 24, surface_vertices_), kVertex, grown));
  if (grown) std::fill(surface_vertex_copy_.begin(), surface_vertex_copy_.end(), glm::vec3(std::nanf("")));
  FIRE_TRY(reserve(surface_indices_, room(VkDeviceSize(surface_quad_end_) * 24, surface_indices_), kIndex, grown));
  if (grown) std::fill(placed.begin(), placed.end(), 1);
  return Status::success();
}

void Renderer::write_surface_vertices(const SurfaceLevels& s, ChangedRange changed) {
  changed.end = std::min(changed.end, s.vertex_count());
  for (const Block& b : blocks_) {
    glm::vec3* held = &surface_vertex_copy_[2 * size_t(b.first_vertex)];
    uint32_t run = kNone;  // first vertex of the run of differing ones being gathered
    auto flush = [&](uint32_t end) {
      copy_into(surface_vertices_, VkDeviceSize(b.first_vertex + run) * 24, &held[2 * size_t(run)],
                VkDeviceSize(end - run) * 24);
      stats_.surface_vertices += end - run;
      run = kNone;
    };
    for (uint32_t i = 0; i < b.vertex_count; ++i) {
      const uint32_t v = b.vertices[i];
      bool differs = false;
      if (v >= changed.begin && v < changed.end) {
        const glm::vec3 p = to_float(s.positions[v]), n = to_float(s.normals[v]);
        if (held[2 * i] != p || held[2 * i + 1] != n) {
          held[2 * i] = p;
          held[2 * i + 1] = n;
          differs = true;
        }
      }
      if (differs && run == kNone) run = i;
      if (!differs && run != kNone) flush(i);
    }
    if (run != kNone) flush(b.vertex_count);
  }
}

Status Renderer::set_stroke(std::span<const Vec3> points) {
  stroke_count_ = 0;
  if (points.size() < 2) return Status::success();
  bool grown = false;
  FIRE_TRY(reserve(stroke_, points.size() * sizeof(glm::vec3), kVertex, grown));
  std::vector<glm::vec3> floats;
  floats.reserve(points.size());
  for (const Vec3& p : points) floats.push_back(to_float(p));
  copy_into(stroke_, 0, floats.data(), floats.size() * sizeof(glm::vec3));
  stroke_count_ = uint32_t(points.size());
  return Status::success();
}

Status Renderer::set_marks(std::span<const Vec3> marks, size_t next) {
  std::vector<glm::vec3> data;
  data.reserve(marks.size());
  for (const Vec3& p : marks) data.push_back(to_float(p));
  next_mark_ = next;
  if (data == marks_copy_) return Status::success();
  if (!data.empty()) {
    bool grown = false;
    FIRE_TRY(reserve(marks_, data.size() * sizeof(glm::vec3), kVertex, grown));
    copy_into(marks_, 0, data.data(), data.size() * sizeof(glm::vec3));
  }
  marks_copy_ = std::move(data);
  return Status::success();
}

Status Renderer::set_pen_feedback(const Mesh& network, const PenFeedback& feedback) {
  std::vector<glm::vec3> data;
  uint32_t fan = 0;
  if (network.valid(feedback.face)) {  // a fan around the boundary's centroid, lit by the boundary's normal
    const std::vector<Vec3> loop = network.face_boundary(FaceIndex{feedback.face.index});
    const LoopPlane plane = loop_plane(loop);
    const glm::vec3 n = plane.normal.norm() > 0 ? to_float(plane.normal) : glm::vec3(0.0f, 0.0f, 1.0f);
    for (size_t i = 0; i < loop.size(); ++i)
      for (const Vec3* p : {&plane.centroid, &loop[i], &loop[(i + 1) % loop.size()]}) {
        data.push_back(to_float(*p));
        data.push_back(n);
      }
    fan = uint32_t(3 * loop.size());
  }
  const bool closes = feedback.closes_border && network.valid(feedback.first_vertex);
  const bool marker = closes || network.valid(feedback.target_edge);
  if (marker) data.push_back(to_float(feedback.target));
  pen_face_vertices_ = fan;
  pen_marker_ = marker;
  pen_closes_ = closes;
  if (data == pen_copy_ || data.empty()) return Status::success();
  bool grown = false;
  FIRE_TRY(reserve(pen_, data.size() * sizeof(glm::vec3), kVertex, grown));
  // The marker comes last: a pen moving along a curve over the same face copies only the marker.
  size_t first = 0;
  if (!grown && data.size() == pen_copy_.size())
    first = size_t(std::mismatch(data.begin(), data.end(), pen_copy_.begin()).first - data.begin());
  copy_into(pen_, first * sizeof(glm::vec3), data.data() + first, (data.size() - first) * sizeof(glm::vec3));
  pen_copy_ = std::move(data);
  return Status::success();
}

Status Renderer::set_reference(std::span<const Vec3> positions, std::span<const uint32_t> triangles) {
  ++scene_version_;
  reference_index_count_ = 0;
  if (triangles.empty()) return Status::success();
  // Area-weighted vertex normals; the shader lights both sides, so orientation does not matter.
  std::vector<glm::vec3> normals(positions.size(), glm::vec3(0.0f));
  for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
    const uint32_t a = triangles[t], b = triangles[t + 1], c = triangles[t + 2];
    if (a >= positions.size() || b >= positions.size() || c >= positions.size())
      return Status::failure("reference mesh: triangle index out of range");
    const glm::vec3 n = glm::cross(to_float(positions[b]) - to_float(positions[a]), to_float(positions[c]) - to_float(positions[a]));
    for (uint32_t v : {a, b, c}) normals[v] += n;
  }
  std::vector<glm::vec3> interleaved;
  for (size_t v = 0; v < positions.size(); ++v) {
    interleaved.push_back(to_float(positions[v]));
    const float length = glm::length(normals[v]);
    interleaved.push_back(length > 0.0f ? normals[v] / length : glm::vec3(0.0f, 0.0f, 1.0f));
  }
  bool grown = false;
  FIRE_TRY(reserve(reference_vertices_, interleaved.size() * sizeof(glm::vec3), kVertex, grown));
  FIRE_TRY(reserve(reference_indices_, triangles.size_bytes(), kIndex, grown));
  std::memcpy(reference_vertices_.mapped, interleaved.data(), interleaved.size() * sizeof(glm::vec3));
  std::memcpy(reference_indices_.mapped, triangles.data(), triangles.size_bytes());
  reference_index_count_ = uint32_t(triangles.size() / 3 * 3);
  return Status::success();
}

namespace {

// Every draw's push constants start from the camera's; line and marker sizes follow the image height so a small
// test image looks like a large one scaled down.
PushConstants camera_constants(const Camera& camera, uint32_t width, uint32_t height) {
  PushConstants pc{};
  pc.view_proj = camera.view_projection();
  pc.eye = glm::vec4(camera.eye, 1.0f);
  pc.params = {0.0f, float(width), float(height), 0.0f};
  pc.light = glm::vec4(camera.key_light, 0.0f);
  return pc;
}

// One pass's draws: each binds its pipeline with the push constants as they are then.
struct Pass {
  VkCommandBuffer cmd;
  VkPipelineLayout layout;
  PushConstants pc;
  void push() const {
    vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof pc, &pc);
  }
  // For `pipeline`'s draws: it, the push constants as they are now, and `vertices` from `offset` on.
  void bind(VkPipeline pipeline, VkBuffer vertices, VkDeviceSize offset = 0) const {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
    push();
    vkCmdBindVertexBuffers(cmd, 0, 1, &vertices, &offset);
  }
};

constexpr VkPipelineStageFlags2 kColorStage = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
constexpr VkAccessFlags2 kColorAccess = VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT;
constexpr VkPipelineStageFlags2 kDepthStage =
    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
constexpr VkAccessFlags2 kDepthAccess =
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;

// An image whose content the frame clears or overwrites whole: from whatever the previous frame did with it.
VkImageMemoryBarrier2 overwrite(VkImage image, VkImageLayout layout, VkImageAspectFlags aspect, VkPipelineStageFlags2 stage,
                                VkAccessFlags2 access) {
  return image_barrier(image, aspect, VK_IMAGE_LAYOUT_UNDEFINED, layout, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0, stage, access);
}

}  // namespace

bool Renderer::LayerKey::operator==(const LayerKey& o) const {
  return view_proj == o.view_proj && eye == o.eye && light == o.light && line_depth_pull == o.line_depth_pull &&
         options.surface == o.options.surface && options.curves == o.options.curves &&
         options.wireframe == o.options.wireframe && scene == o.scene;
}

void Renderer::begin_rendering(VkCommandBuffer cmd, VkImageView color_view, VkImageView resolve_view, VkImageView depth_view,
                               bool clear, bool keep) {
  VkRenderingAttachmentInfo color{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  color.imageView = color_view;
  color.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  color.loadOp = clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;  // the background: a clear, no full-screen shading on lavapipe
  const glm::vec4 background = linear(Palette::background);
  color.clearValue.color = {{background.r, background.g, background.b, 1.0f}};
  color.storeOp = keep || !resolve_view ? VK_ATTACHMENT_STORE_OP_STORE : VK_ATTACHMENT_STORE_OP_DONT_CARE;
  if (resolve_view) {
    color.resolveMode = VK_RESOLVE_MODE_AVERAGE_BIT;
    color.resolveImageView = resolve_view;
    color.resolveImageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  }
  VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  depth.imageView = depth_view;
  depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
  depth.loadOp = clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
  depth.storeOp = keep ? VK_ATTACHMENT_STORE_OP_STORE : VK_ATTACHMENT_STORE_OP_DONT_CARE;
  depth.clearValue.depthStencil = {1.0f, 0};
  VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
  rendering.renderArea = {{0, 0}, {settings_.width, settings_.height}};
  rendering.layerCount = 1;
  rendering.colorAttachmentCount = 1;
  rendering.pColorAttachments = &color;
  rendering.pDepthAttachment = &depth;
  vkCmdBeginRendering(cmd, &rendering);
  VkViewport viewport{0.0f, 0.0f, float(settings_.width), float(settings_.height), 0.0f, 1.0f};
  VkRect2D scissor{{0, 0}, {settings_.width, settings_.height}};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &scissor);
}

namespace {

// The quads one level coarser (4 indices each): every group of four consecutive quads, the children of one
// quad, becomes the quad of the corners that no other quad of its group uses, child by child. False where the
// quads do not group so.
bool coarsen(std::span<const uint32_t> fine, std::vector<uint32_t>& out) {
  if (fine.size() % 16 != 0) return false;
  out.clear();
  for (size_t group = 0; group < fine.size(); group += 16) {
    const std::span<const uint32_t> children = fine.subspan(group, 16);
    for (size_t child = 0; child < 4; ++child) {
      uint32_t corner = kNone;
      for (size_t i = 0; i < 4; ++i) {
        const uint32_t v = children[4 * child + i];
        if (std::count(children.begin(), children.end(), v) != 1) continue;
        if (corner != kNone) return false;
        corner = v;
      }
      if (corner == kNone) return false;
      out.push_back(corner);
    }
  }
  return true;
}

}  // namespace

uint32_t Renderer::coarser_step(const Camera& camera) const {
  if (surface_level_ < 2 || blocks_.empty() || !(surface_radius_ > 0)) return 0;
  const float pixel = pixel_size_at(camera, surface_centre_, settings_.height);
  if (!(pixel > 0)) return 0;
  // The quads' size on screen, roughly: the surface's bounding disc shared by the half of its quads facing the camera.
  const float radius_px = surface_radius_ / pixel;
  const float quad_px = std::sqrt(std::numbers::pi_v<float> * radius_px * radius_px / (0.5f * float(std::max(surface_quads_, 1u))));
  uint32_t step = 0;
  while (step + 1 < surface_level_ && quad_px * float(1u << step) < kCoarseQuadPx) ++step;
  return step;
}

bool Renderer::build_coarse(uint32_t step) {
  if (coarse_.size() < step) coarse_.resize(step);
  Coarse& c = coarse_[step - 1];
  if (c.built && c.layout == surface_layout_) return c.index_count > 0;
  c.built = true;
  c.layout = surface_layout_;
  c.index_count = 0;
  std::vector<uint32_t> indices, quads, coarser;
  for (const Block& b : blocks_) {
    quads = b.quads;
    for (uint32_t k = 0; k < step; ++k) {
      if (!coarsen(quads, coarser)) return false;
      quads.swap(coarser);
    }
    for (size_t q = 0; q < quads.size(); q += 4)
      for (size_t corner : {0, 1, 2, 0, 2, 3}) indices.push_back(b.first_vertex + quads[q + corner]);
  }
  const VkDeviceSize bytes = VkDeviceSize(indices.size()) * sizeof(uint32_t);
  bool grown = false;
  if (indices.empty() || !reserve(c.indices, bytes, kIndex, grown)) return false;
  copy_into(c.indices, 0, indices.data(), bytes);
  c.index_count = uint32_t(indices.size());
  return true;
}

void Renderer::record_layer(VkCommandBuffer cmd, const Camera& camera, const DrawOptions& options, uint32_t step) {
  const float scale = float(settings_.height) / 720.0f;
  Pass pass{cmd, layout_, camera_constants(camera, settings_.width, settings_.height)};
  PushConstants& pc = pass.pc;
  auto draw_surface = [&] {
    if (step > 0) {
      vkCmdBindIndexBuffer(cmd, coarse_[step - 1].indices.buffer, 0, VK_INDEX_TYPE_UINT32);
      vkCmdDrawIndexed(cmd, coarse_[step - 1].index_count, 1, 0, 0, 0);
      return;
    }
    vkCmdBindIndexBuffer(cmd, surface_indices_.buffer, 0, VK_INDEX_TYPE_UINT32);
    for (const auto& [first, count] : surface_draws_) vkCmdDrawIndexed(cmd, count, 1, first, 0, 0);
  };
  if (!surface_draws_.empty() && options.surface) {
    pc.color = linear(surface_settled_ ? Palette::surface : Palette::provisional_surface);
    pass.bind(surface_, surface_vertices_.buffer);
    draw_surface();
  }
  if (!surface_draws_.empty() && options.wireframe && wireframe_) {
    pc.color = linear(Palette::wireframe);
    pass.bind(wireframe_, surface_vertices_.buffer);
    draw_surface();
  }
  if (!curve_draws_.empty() && options.curves) {
    pc.color = linear(Palette::curve);
    pc.params.x = std::max(1.0f, 1.6f * scale);
    pc.params.w = camera.line_depth_pull;
    pass.bind(curves_, points_.buffer);
    for (const auto& [first, count] : curve_draws_) vkCmdDraw(cmd, 6, count - 1, 0, first);
  }
  if (!pending_draws_.empty() && options.curves) {  // as the stroke being drawn: not yet a curve
    pc.color = linear(Palette::stroke);
    pc.params.x = std::max(1.0f, 2.0f * scale);
    pc.params.w = camera.line_depth_pull;
    pass.bind(curves_, points_.buffer);
    for (const auto& [first, count] : pending_draws_) vkCmdDraw(cmd, 6, count - 1, 0, first);
  }
  if (!marker_draws_.empty() && options.curves) {
    pc.color = linear(Palette::marker);
    pc.params.x = std::max(2.5f, 4.5f * scale);
    pc.params.w = camera.line_depth_pull * 2.0f;
    pass.bind(markers_, vertices_.buffer);
    for (const auto& [first, count] : marker_draws_) vkCmdDraw(cmd, 6, count, 0, first);
  }
  if (reference_index_count_) {
    pc.color = linear(Palette::reference, 0.35f);
    pass.bind(reference_pipeline_, reference_vertices_.buffer);
    vkCmdBindIndexBuffer(cmd, reference_indices_.buffer, 0, VK_INDEX_TYPE_UINT32);
    vkCmdDrawIndexed(cmd, reference_index_count_, 1, 0, 0, 0);
  }
}

void Renderer::record_overlays(VkCommandBuffer cmd, const Camera& camera) {
  const float scale = float(settings_.height) / 720.0f;
  Pass pass{cmd, layout_, camera_constants(camera, settings_.width, settings_.height)};
  PushConstants& pc = pass.pc;
  if (pen_face_vertices_) {  // over the see-through reference, which would wash it out
    pc.color = linear(Palette::pen_face, Palette::pen_face_alpha);
    pass.bind(pen_face_, pen_.buffer);
    vkCmdDraw(cmd, pen_face_vertices_, 1, 0, 0);
  }
  if (stroke_count_) {  // after the see-through reference, so the pen's trace shows in full
    pc.color = linear(Palette::stroke);
    pc.params.x = std::max(1.0f, 2.0f * scale);
    pc.params.w = camera.line_depth_pull * 2.0f;
    pass.bind(curves_, stroke_.buffer);
    vkCmdDraw(cmd, 6, stroke_count_ - 1, 0, 0);
  }
  if (!marks_copy_.empty()) {  // over the surface, so a mark under it still shows where to touch
    const auto count = uint32_t(marks_copy_.size());
    pc.color = linear(Palette::mark);
    pc.params.x = std::max(3.0f, 6.0f * scale);
    pc.params.w = camera.line_depth_pull * 3.0f;
    pass.bind(markers_, marks_.buffer);
    vkCmdDraw(cmd, 6, count, 0, 0);
    if (next_mark_ < count) {
      pc.color = linear(Palette::next_mark);
      pc.params.x = std::max(5.0f, 11.0f * scale);
      pass.push();
      vkCmdDraw(cmd, 6, 1, 0, uint32_t(next_mark_));
    }
  }
  if (pen_marker_) {  // last: the marker says where the stroke will end, over the stroke itself
    pc.color = linear(pen_closes_ ? Palette::close_border : Palette::snap_target);
    pc.params.x = std::max(4.0f, (pen_closes_ ? 10.0f : 7.5f) * scale);
    pc.params.w = camera.line_depth_pull * 3.0f;
    pass.bind(markers_, pen_.buffer, VkDeviceSize(2 * pen_face_vertices_) * sizeof(glm::vec3));
    vkCmdDraw(cmd, 6, 1, 0, 0);
  }
}

void Renderer::record(VkCommandBuffer cmd, const Camera& camera, const DrawOptions& options, VkImage target,
                      VkImageView target_view, bool target_takes_copies) {
  const LayerKey key{camera.view_projection(), camera.eye, camera.key_light, camera.line_depth_pull, options, scene_version_};
  const bool still = last_key_ && *last_key_ == key;
  const bool moved = last_key_ && (last_key_->view_proj != key.view_proj || last_key_->eye != key.eye);
  last_key_ = key;
  drawn_step_ = settings_.coarser_while_moving && moved ? coarser_step(camera) : 0;
  if (drawn_step_ > 0 && !build_coarse(drawn_step_)) drawn_step_ = 0;
  const VkImage frame_color = color_.image ? color_.image : target;
  const VkImageView frame_view = color_.image ? color_.view : target_view;
  const VkImageView resolve_view = color_.image ? target_view : VK_NULL_HANDLE;
  std::vector<VkImageMemoryBarrier2> barriers;
  if (!still || !(color_.image || target_takes_copies)) {
    // A frame unlike the one before: drawn whole into the frame's targets, as no layer would be used twice.
    layer_ready_ = false;
    layer_uses_ = 0;
    barriers.push_back(overwrite(target, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_ASPECT_COLOR_BIT, kColorStage, kColorAccess));
    if (color_.image)
      barriers.push_back(overwrite(color_.image, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_ASPECT_COLOR_BIT, kColorStage, kColorAccess));
    barriers.push_back(overwrite(depth_.image, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_IMAGE_ASPECT_DEPTH_BIT, kDepthStage, kDepthAccess));
    record_barriers(cmd, barriers);
    begin_rendering(cmd, frame_view, resolve_view, depth_.view, true, false);
    record_layer(cmd, camera, options, drawn_step_);
    record_overlays(cmd, camera);
    vkCmdEndRendering(cmd);
    return;
  }
  // A still frame: the layer (everything but the pen's feedback, the stroke and the marks) is drawn once into
  // images of its own, then copied into each frame, and only the rest is drawn over it.
  if (!layer_ready_) {
    barriers.push_back(overwrite(layer_color_.image, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_ASPECT_COLOR_BIT, kColorStage, kColorAccess));
    barriers.push_back(overwrite(layer_depth_.image, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_IMAGE_ASPECT_DEPTH_BIT, kDepthStage, kDepthAccess));
    record_barriers(cmd, barriers);
    barriers.clear();
    begin_rendering(cmd, layer_color_.view, VK_NULL_HANDLE, layer_depth_.view, true, true);
    record_layer(cmd, camera, options, 0);
    vkCmdEndRendering(cmd);
    barriers.push_back(image_barrier(layer_color_.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                     VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, kColorStage, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                                     VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT));
    barriers.push_back(image_barrier(layer_depth_.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                                     VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, kDepthStage, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                                     VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT));
    layer_ready_ = true;
  }
  ++layer_uses_;
  barriers.push_back(overwrite(frame_color, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_ASPECT_COLOR_BIT,
                               VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT));
  barriers.push_back(overwrite(depth_.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_ASPECT_DEPTH_BIT,
                               VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT));
  if (color_.image)
    barriers.push_back(overwrite(target, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_ASPECT_COLOR_BIT, kColorStage, kColorAccess));
  record_barriers(cmd, barriers);
  barriers.clear();
  auto copy = [&](VkImage from, VkImage to, VkImageAspectFlags aspect) {
    VkImageCopy region{};
    region.srcSubresource = {aspect, 0, 0, 1};
    region.dstSubresource = {aspect, 0, 0, 1};
    region.extent = {settings_.width, settings_.height, 1};
    vkCmdCopyImage(cmd, from, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, to, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  };
  copy(layer_color_.image, frame_color, VK_IMAGE_ASPECT_COLOR_BIT);
  copy(layer_depth_.image, depth_.image, VK_IMAGE_ASPECT_DEPTH_BIT);
  barriers.push_back(image_barrier(frame_color, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                   VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
                                   VK_ACCESS_2_TRANSFER_WRITE_BIT, kColorStage, kColorAccess));
  barriers.push_back(image_barrier(depth_.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                   VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
                                   VK_ACCESS_2_TRANSFER_WRITE_BIT, kDepthStage, kDepthAccess));
  record_barriers(cmd, barriers);
  begin_rendering(cmd, frame_view, resolve_view, depth_.view, false, false);
  record_overlays(cmd, camera);
  vkCmdEndRendering(cmd);
}

Status Renderer::draw(const Camera& camera, const DrawOptions& options) {
  VkDevice device = context_.device();
  VkCommandBuffer cmd = commands_;
  FIRE_VK_TRY(vkResetFences(device, 1, &fence_));
  FIRE_VK_TRY(vkResetCommandBuffer(cmd, 0));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  FIRE_VK_TRY(vkBeginCommandBuffer(cmd, &begin));
  record(cmd, camera, options, resolve_.image, resolve_.view, true);
  record_readback(cmd, resolve_.image, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, {settings_.width, settings_.height},
                  readback_.buffer);
  FIRE_VK_TRY(vkEndCommandBuffer(cmd));

  VkCommandBufferSubmitInfo command{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  command.commandBuffer = cmd;
  VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  submit.commandBufferInfoCount = 1;
  submit.pCommandBufferInfos = &command;
  FIRE_VK_TRY(vkQueueSubmit2(context_.queue(), 1, &submit, fence_));
  FIRE_VK_TRY(vkWaitForFences(device, 1, &fence_, VK_TRUE, kFenceTimeoutNs));
  return Status::success();
}

Image Renderer::image() const {
  Image out{settings_.width, settings_.height, {}};
  const auto* bytes = static_cast<const uint8_t*>(readback_.mapped);
  out.rgba.assign(bytes, bytes + size_t(settings_.width) * settings_.height * 4);
  if (color_format_ == VK_FORMAT_B8G8R8A8_SRGB)
    for (size_t i = 0; i < out.rgba.size(); i += 4) std::swap(out.rgba[i], out.rgba[i + 2]);
  return out;
}

}  // namespace fire::render
