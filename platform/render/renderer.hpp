#pragma once
// The renderer: reads the curve network's pools and SurfaceLevels and draws them into an offscreen
// target (colour and depth, multisampled on a GPU and resolved; read back to the CPU).
//
// What it draws, back to front: a neutral background (cleared); the surface, lit (two-sided Blinn-Phong)
// and tinted while it is provisional (SurfaceLevels::settled false); every live edge's polyline as a
// screen-space line pulled slightly towards the camera so it shows on the surface it lies on; the
// network's vertices as round markers; an optional see-through reference mesh; the pen's feedback
// (engine/pen_feedback.hpp): the face under the pen tinted see-through over everything but the stroke, the snap target as a
// large marker, and the border's first vertex as a larger one when a stroke ending at the pen would close it;
// in a live session the object's registration marks, the one to touch next larger and red.
// A frame the same as the one before but for the stroke, the pen's feedback and the marks (record()) copies
// the rest from the layer it kept, so a still scene is rasterised once. A frame whose camera moved may draw
// the surface at a coarser level (RenderSettings::coarser_while_moving); no other frame does.
//
// Uploads copy only what changed and count the bytes (UploadStats, per upload() call, i.e. per frame):
// - points: the GPU keeps a float copy of the point pool at the pool's indices. An edge's points are
//   copied when the edge is new to the renderer, its slot's generation, offset or count moved, or it is
//   stamped (engine/change.hpp) after the network frame of the previous upload;
// - network vertices: by slot, when new or their position changed;
// - surface: in blocks, one per patch (SurfaceLevels' quads grouped by network face), each holding its
//   patch's vertices (those on a patch border once per patch) and triangles. When topology_version moved
//   (or on first sight) a patch whose key and quads, renumbered in the order they appear, are those of a
//   block keeps that block; the others get a freed block that fits or space at the end, and their
//   triangles are copied. Then, and when SurfaceLevels::frame is newer than the last frame uploaded, the
//   vertices in SurfaceLevels::changed are converted to float and copied where they differ from what the
//   block holds: a commit copies the triangles of the patches it changed and the vertices whose values
//   moved (the limit fit moves most of them a little at every commit: perf/notes/render.md);
// - the surface's coarser levels (RenderSettings::coarser_while_moving): their triangles, in the first frame
//   that draws one after the blocks were laid out, counted with that frame's upload.
// Buffers are host-visible; growing one re-uploads its whole content (counted as well). The surface's
// buffers grow by half again, and are laid out afresh when freed blocks outnumber the used ones.
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "engine/mesh.hpp"
#include "engine/pen_feedback.hpp"
#include "engine/surface.hpp"
#include "platform/render/camera.hpp"
#include "platform/render/context.hpp"
#include "platform/render/image.hpp"

namespace fire::render {

struct RenderSettings {
  uint32_t width = 1280, height = 720;
  // Samples per pixel (1, 2, 4 or 8; the largest the device has, up to this). 0: the environment's
  // FIRE_SAMPLES if set, else by device: 1 on a CPU device (lavapipe, where 4x samples cost much of the
  // frame: perf/notes/render.md), 4 on a GPU.
  uint32_t samples = 0;
  // The colour format drawn in: the window's swapchain format for the present path (R8G8B8A8_SRGB or
  // B8G8R8A8_SRGB; image() returns RGBA either way).
  VkFormat color_format = VK_FORMAT_R8G8B8A8_SRGB;
  // A frame whose camera moved since the frame before draws the surface at a coarser level, chosen by how
  // large its quads are on screen (at least kCoarseQuadPx across while the camera moves); every other frame
  // draws the surface's own level. For the app's window, where a drag turns the camera every frame.
  bool coarser_while_moving = false;
};

// While the camera moves, the surface is drawn at the finest level whose quads are about this many pixels
// across or more (RenderSettings::coarser_while_moving).
inline constexpr float kCoarseQuadPx = 4.0f;

// Colours of the scene, sRGB 0..255: shared with the tests, which find the curves and the background by them.
struct Palette {
  static constexpr uint8_t background[3] = {46, 49, 54};
  static constexpr uint8_t curve[3] = {255, 140, 26};
  static constexpr uint8_t surface[3] = {196, 200, 206};
  static constexpr uint8_t provisional_surface[3] = {132, 196, 214};  // light teal: not settled yet
  static constexpr uint8_t marker[3] = {250, 250, 250};
  static constexpr uint8_t reference[3] = {120, 170, 255};
  static constexpr uint8_t wireframe[3] = {40, 44, 52};
  static constexpr uint8_t stroke[3] = {255, 220, 60};  // the stroke being drawn, and pieces pending: not yet a curve
  static constexpr uint8_t pen_face[3] = {255, 70, 200};       // tint of the face under the pen
  static constexpr uint8_t snap_target[3] = {40, 225, 255};    // where a stroke end at the pen snaps
  static constexpr uint8_t close_border[3] = {70, 235, 110};   // the first vertex, when a stroke end closes the border
  static constexpr uint8_t mark[3] = {170, 120, 255};          // the object's registration marks
  static constexpr uint8_t next_mark[3] = {255, 60, 60};       // the mark to touch next
  static constexpr float pen_face_alpha = 0.4f;
};

// What a frame shows: the app's toggles. The wireframe (the surface's quads as lines) needs the device's
// fillModeNonSolid (Context::wireframe_supported); without it the wireframe is not drawn.
struct DrawOptions {
  bool surface = true, curves = true, wireframe = false;
};

struct UploadStats {
  uint64_t bytes = 0;              // copied into GPU buffers by the last upload()
  uint32_t edges = 0;              // edges whose points were copied
  uint32_t vertices = 0;           // network vertex markers copied
  uint32_t surface_vertices = 0;   // surface vertices copied
  uint32_t surface_quads = 0;      // surface quads whose triangle indices were copied
};

class Renderer {
 public:
  static Result<std::unique_ptr<Renderer>> create(Context& context, const RenderSettings& settings = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Brings the GPU copies of the network and the surface up to date (see the top of this file).
  Status upload(const Mesh& network, const SurfaceLevels& surface);
  const UploadStats& last_upload() const { return stats_; }
  // The stroke in progress (the sketch's samples since pen down), drawn over everything else; empty: none.
  // Its points are copied whole each call, after upload() so they count in last_upload(): a stroke is short
  // next to the scene.
  Status set_stroke(std::span<const Vec3> points);
  // The pen's feedback as the sketch system published it for `network`; elements whose handle no longer
  // holds are not drawn. Copies from the first value that changed since the last call (the marker alone while the
  // pen moves over one face), counted in last_upload().
  Status set_pen_feedback(const Mesh& network, const PenFeedback& feedback);
  // The object's registration marks, the one at `next` larger and in its own colour (none: no highlight);
  // empty: none. Copied whole when they change: a handful of points.
  Status set_marks(std::span<const Vec3> marks, size_t next);
  // A mesh drawn see-through over the scene (triangles: 3 indices each); empty triangles removes it.
  Status set_reference(std::span<const Vec3> positions, std::span<const uint32_t> triangles);

  // Draws one frame and waits for it; the result is then in image().
  Status draw(const Camera& camera, const DrawOptions& options = {});
  Image image() const;
  // The present path (present.hpp): records the frame into `cmd` without submitting it, drawn (or resolved)
  // straight into `target`, an image of color_format() and width() x height() (a swapchain image: no copy of
  // the frame on the way). `target` is left in COLOR_ATTACHMENT_OPTIMAL, written at COLOR_ATTACHMENT_OUTPUT.
  // A still frame (the camera, the options and what upload() and set_reference() gave unchanged since the
  // frame before) is not drawn again: the layer of everything but the stroke, the pen's feedback and the marks
  // is drawn once into images of the renderer's own and copied into every frame after it, and only those are
  // drawn over it, with the same pixels as a frame drawn whole. Without a multisampled target this needs
  // `target_takes_copies` (TRANSFER_DST usage); else every frame is drawn whole.
  void record(VkCommandBuffer cmd, const Camera& camera, const DrawOptions& options, VkImage target,
              VkImageView target_view, bool target_takes_copies);
  // How many frames in a row were still frames, copied from the layer (0 after a frame drawn whole).
  uint64_t layer_frames() const { return layer_uses_; }
  // How many levels coarser than its own the last frame drew the surface (0: its own level).
  uint32_t coarser_levels() const { return drawn_step_; }
  VkFormat color_format() const { return color_format_; }
  // New target size (a resized window); waits for the device first. Uploaded data is kept.
  Status resize(uint32_t width, uint32_t height);

  uint32_t width() const { return settings_.width; }
  uint32_t height() const { return settings_.height; }
  VkSampleCountFlagBits samples() const { return samples_; }

  struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
    VkDeviceSize capacity = 0;
  };
  struct Target {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
  };

 private:
  explicit Renderer(Context& context, const RenderSettings& settings)
      : context_(context), settings_(settings), color_format_(settings.color_format) {}
  Status init();
  Status create_targets();
  Status create_target(Target& target, VkFormat format, VkImageUsageFlags usage, VkSampleCountFlagBits samples,
                       VkImageAspectFlags aspect);
  // Makes `buffer` hold at least `bytes`; `grown` tells whether its old content was lost.
  Status reserve(Buffer& buffer, VkDeviceSize bytes, VkBufferUsageFlags usage, bool& grown);
  void destroy(Buffer& buffer);
  void destroy(Target& target);
  Status create_pipelines();
  void begin_rendering(VkCommandBuffer cmd, VkImageView color_view, VkImageView resolve_view, VkImageView depth_view,
                       bool clear, bool keep);
  void record_layer(VkCommandBuffer cmd, const Camera& camera, const DrawOptions& options, uint32_t step);
  // How many levels coarser a frame whose camera moved draws the surface (RenderSettings::coarser_while_moving).
  uint32_t coarser_step(const Camera& camera) const;
  // Makes coarse_[step - 1] hold the surface's triangles `step` levels coarser; false where it cannot.
  bool build_coarse(uint32_t step);
  void record_overlays(VkCommandBuffer cmd, const Camera& camera);
  void copy_into(Buffer& buffer, VkDeviceSize offset, const void* data, VkDeviceSize bytes);
  Status upload_points(const Mesh& network);
  Status upload_vertices(const Mesh& network);
  Status upload_surface(const SurfaceLevels& surface);
  Status layout_surface(const SurfaceLevels& surface);
  // Makes the surface buffers hold the blocks; where one had to grow, every block is copied again.
  Status reserve_surface(std::vector<uint8_t>& placed);
  void write_surface_vertices(const SurfaceLevels& surface, ChangedRange changed);

  Context& context_;
  RenderSettings settings_;
  VkSampleCountFlagBits samples_ = VK_SAMPLE_COUNT_1_BIT;
  VkFormat color_format_ = VK_FORMAT_R8G8B8A8_SRGB;
  VkFormat depth_format_ = VK_FORMAT_D32_SFLOAT;
  Target color_, resolve_, depth_;
  // The still frame's layer, and what it was drawn for.
  struct LayerKey {
    glm::mat4 view_proj;
    glm::vec3 eye, light;
    float line_depth_pull;
    DrawOptions options;
    uint64_t scene;
    bool operator==(const LayerKey& other) const;
  };
  Target layer_color_, layer_depth_;
  std::optional<LayerKey> last_key_;  // the previous frame's
  bool layer_ready_ = false;          // the layer images hold last_key_'s layer
  uint64_t layer_uses_ = 0;
  uint64_t scene_version_ = 0;        // moves whenever upload() or set_reference() changes what the layer shows
  Buffer readback_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer commands_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline surface_ = VK_NULL_HANDLE, reference_pipeline_ = VK_NULL_HANDLE,
             curves_ = VK_NULL_HANDLE, markers_ = VK_NULL_HANDLE, wireframe_ = VK_NULL_HANDLE,
             pen_face_ = VK_NULL_HANDLE;

  // Network: float points at pool indices, and what was uploaded per edge slot.
  struct EdgeRecord {
    uint32_t generation = kNone, offset = 0, count = 0;
  };
  Buffer points_;
  std::vector<EdgeRecord> edge_records_;
  Frame network_frame_ = 0;  // the network's frame at the last upload: later stamps are news
  std::vector<std::pair<uint32_t, uint32_t>> curve_draws_;  // (first point, point count) per live edge of the network
  std::vector<std::pair<uint32_t, uint32_t>> pending_draws_;  // the same per pending piece (Mesh::pending_chains)
  Buffer vertices_;
  std::vector<glm::vec3> vertex_copy_;  // what the vertex buffer holds, per slot
  std::vector<uint8_t> vertex_live_;
  std::vector<std::pair<uint32_t, uint32_t>> marker_draws_;  // runs of live vertex slots (first, count)

  // Surface: interleaved float position and normal per vertex, 6 indices per quad, in blocks per patch.
  struct Block {
    uint32_t key = kNone;
    uint32_t first_vertex = 0, vertex_count = 0, first_quad = 0, quad_count = 0;  // where it lies in the buffers
    std::vector<uint32_t> vertices;  // the surface's vertex held at each of the block's vertices
    std::vector<uint32_t> quads;     // 4 block vertices per quad: the patch's topology
  };
  Buffer surface_vertices_, surface_indices_;
  std::vector<glm::vec3> surface_vertex_copy_;  // what surface_vertices_ holds, up to surface_vertex_end_
  std::vector<uint32_t> surface_index_copy_;    // what surface_indices_ holds, up to 6 * surface_quad_end_
  std::vector<Block> blocks_, free_blocks_;     // free blocks hold their ranges only
  uint32_t surface_vertex_end_ = 0, surface_quad_end_ = 0;  // the buffers' used extent
  std::vector<uint32_t> block_vertex_;  // scratch: per surface vertex its block vertex, kNone outside the patch
  std::vector<std::pair<uint32_t, uint32_t>> surface_draws_;  // (first index, index count), runs of blocks
  uint64_t surface_topology_ = 0;
  // The surface `step` levels coarser (coarse_[step - 1]), for frames whose camera moved: each quad the corners
  // of a group of four quads one level finer that no other quad of the group uses (catmull_clark's children of
  // one quad), over the same vertices. Those are limit positions, so this is the coarser level's limit mesh.
  // Built in the first frame that wants it after the blocks were laid out (surface_layout_).
  struct Coarse {
    Buffer indices;
    uint32_t index_count = 0;  // 0: the blocks' quads do not group so
    uint64_t layout = 0;
    bool built = false;
  };
  std::vector<Coarse> coarse_;
  uint64_t surface_layout_ = 0;  // moves whenever the blocks are laid out
  uint32_t surface_level_ = 0, surface_quads_ = 0;
  glm::vec3 surface_centre_{0.0f};
  float surface_radius_ = 0;
  uint32_t drawn_step_ = 0;
  Frame surface_frame_ = 0;
  bool surface_seen_ = false;
  bool surface_settled_ = true;

  Buffer stroke_;
  uint32_t stroke_count_ = 0;
  // Pen feedback: the face's triangle fan (position and normal per vertex), then the marker's position.
  Buffer pen_;
  std::vector<glm::vec3> pen_copy_;  // what pen_ holds
  uint32_t pen_face_vertices_ = 0;
  bool pen_marker_ = false, pen_closes_ = false;
  Buffer marks_;
  std::vector<glm::vec3> marks_copy_;  // what marks_ holds
  size_t next_mark_ = 0;
  Buffer reference_vertices_, reference_indices_;
  uint32_t reference_index_count_ = 0;

  UploadStats stats_;
};

}  // namespace fire::render
