// The renderer on whatever Vulkan device the machine has (lavapipe in CI), validation layer on: images of
// the demo network checked against expected PNGs and by pixel statistics, uploads by changed range, the
// provisional tint, error messages. Any validation message fails the test.
//
// FIRE_UPDATE_RENDER_EXPECTED=1 rewrites tests/platform/render/expected/ and fails, so an update never passes:
// look at the images, commit them, and run again without it.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>

// VkBufferCreateInfo below is zero-filled after sType on purpose, the Vulkan idiom.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

#include "platform/network_file.hpp"
#include "platform/render/renderer.hpp"
#include "systems/reconstruct/reconstruct.hpp"

using namespace fire;
using namespace fire::render;

#if defined(__SANITIZE_ADDRESS__)
// LeakSanitizer reads its options from here too: the suppressions for Mesa, LLVM and the Vulkan loader.
extern "C" const char* __lsan_default_options() { return "suppressions=" FIRE_LSAN_SUPPRESSIONS; }
#endif

namespace {

const std::string kDir = FIRE_RENDER_TEST_DIR;
constexpr uint32_t kWidth = 320, kHeight = 180;

std::unique_ptr<Context> make_context() {
  auto c = Context::create({.validation = true});
  INFO(c.error());
  REQUIRE(c);
  return std::move(*c);
}

struct Scene {
  Mesh network;
  SurfaceLevels surface;
};

Scene demo_scene() {
  auto net = load_network(kDir + "/data/sketch.fnet");
  INFO(net.error());
  REQUIRE(net);
  Scene s{std::move(*net), {}};
  auto built = reconstruct::reconstruct_surface(s.network, {});
  INFO(built.error());
  REQUIRE(built);
  REQUIRE(assign_quads(*built, 1, s.surface));
  return s;
}

Box box_of(const Scene& s) {
  Box box;
  for (const Vec3& p : s.network.points.values()) box.add(p);
  for (const Vec3& p : s.surface.positions) box.add(p);
  return box;
}

Image render_scene(Context& context, Renderer& renderer, const Scene& s, View view) {
  REQUIRE(renderer.upload(s.network, s.surface));
  Status drawn = renderer.draw(frame_box(box_of(s), view, renderer.width(), renderer.height()));
  INFO(drawn.error);
  REQUIRE(drawn);
  CHECK(context.validation_message_count() == 0);
  return renderer.image();
}

bool is_background(const Image& im, uint32_t x, uint32_t y) {
  for (int k = 0; k < 3; ++k)
    if (std::abs(int(im.pixel(x, y)[k]) - int(Palette::background[k])) > 4) return false;
  return true;
}
bool near(const uint8_t* p, const uint8_t (&c)[3], int tolerance) {
  for (int k = 0; k < 3; ++k)
    if (std::abs(int(p[k]) - int(c[k])) > tolerance) return false;
  return true;
}

struct Rect {
  float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f;
  void add(float x, float y) {
    x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
  }
  bool contains(float x, float y, float inset) const { return x >= x0 + inset && x <= x1 - inset && y >= y0 + inset && y <= y1 - inset; }
};

// Pixels of two images of one size whose colour differs by more than 48 in some channel.
size_t pixels_differing(const Image& a, const Image& b) {
  size_t differing = 0;
  for (size_t i = 0; i < a.rgba.size(); i += 4)
    for (int k = 0; k < 3; ++k)
      if (std::abs(int(a.rgba[i + k]) - int(b.rgba[i + k])) > 48) {
        ++differing;
        break;
      }
  return differing;
}

// Compares with the committed image (or rewrites it on request, and fails): at most 1% of the pixels differ by
// more than 48 in a channel (edges may move by a pixel between driver versions), and the mean difference is small.
void check_expected(const Image& image, const std::string& name) {
  const std::string path = kDir + "/expected/" + name;
  if (const char* update = std::getenv("FIRE_UPDATE_RENDER_EXPECTED"); update && std::string(update) == "1") {
    REQUIRE(write_png(image, path));
    FAIL("rewrote " << path << ": look at it, commit it and run again without FIRE_UPDATE_RENDER_EXPECTED");
  }
  auto expected = read_png(path);
  INFO(expected.error());
  REQUIRE(expected);
  REQUIRE(expected->width == image.width);
  REQUIRE(expected->height == image.height);
  size_t differing = 0;
  double sum = 0;
  for (size_t i = 0; i < image.rgba.size(); i += 4) {
    int worst = 0;
    for (int k = 0; k < 3; ++k) {
      const int d = std::abs(int(image.rgba[i + k]) - int(expected->rgba[i + k]));
      worst = std::max(worst, d);
      sum += d;
    }
    if (worst > 48) ++differing;
  }
  const size_t pixels = image.rgba.size() / 4;
  INFO(name << ": " << differing << " of " << pixels << " pixels differ, mean channel difference "
            << sum / (3.0 * pixels));
  CHECK(differing <= pixels / 100);
  CHECK(sum / (3.0 * pixels) < 2.0);
}

}  // namespace

TEST_CASE("the demo network renders as expected from two views, with the surface, curves and markers where they belong") {
  auto context = make_context();
  auto renderer = Renderer::create(*context, {kWidth, kHeight});
  INFO(renderer.error());
  REQUIRE(renderer);
  const Scene scene = demo_scene();
  for (View view : {View::Iso, View::Top}) {
    const std::string name = view == View::Iso ? "sketch_iso.png" : "sketch_top.png";
    SECTION(name) {
      const Image image = render_scene(*context, **renderer, scene, view);
      check_expected(image, name);

      // The background at the four corners.
      for (uint32_t x : {0u, kWidth - 1})
        for (uint32_t y : {0u, kHeight - 1}) CHECK(is_background(image, x, y));

      // Where the surface should land: its vertices projected with the same camera.
      const Camera camera = frame_box(box_of(scene), view, kWidth, kHeight);
      Rect projected;
      for (const Vec3& p : scene.surface.positions) {
        glm::vec2 q = project_to_pixels(camera, p, kWidth, kHeight);
        projected.add(q.x, q.y);
      }
      Rect drawn;
      size_t inside = 0, covered = 0, curve = 0, curve_inside = 0, marker = 0;
      for (uint32_t y = 0; y < kHeight; ++y)
        for (uint32_t x = 0; x < kWidth; ++x) {
          const bool bg = is_background(image, x, y);
          const float cx = x + 0.5f, cy = y + 0.5f;
          if (!bg) drawn.add(cx, cy);
          if (projected.contains(cx, cy, 0)) {
            ++inside;
            covered += !bg;
          }
          if (near(image.pixel(x, y), Palette::curve, 40)) {
            ++curve;
            curve_inside += projected.contains(cx, cy, 6);
          }
          marker += near(image.pixel(x, y), Palette::marker, 12);
        }
      INFO("projected surface box " << projected.x0 << "," << projected.y0 << " .. " << projected.x1 << ","
                                    << projected.y1 << "; drawn box " << drawn.x0 << "," << drawn.y0 << " .. "
                                    << drawn.x1 << "," << drawn.y1);
      // What is drawn spans the surface's projection, up to a marker's radius (2.5 px here) and a pixel.
      constexpr float kSlack = 4.5f;
      CHECK(std::abs(drawn.x0 - projected.x0) <= kSlack);
      CHECK(std::abs(drawn.x1 - projected.x1) <= kSlack);
      CHECK(std::abs(drawn.y0 - projected.y0) <= kSlack);
      CHECK(std::abs(drawn.y1 - projected.y1) <= kSlack);
      // The surface fills its box: a square seen from above, a diamond seen from the side.
      const double coverage = double(covered) / double(inside);
      INFO("coverage " << coverage << ", curve pixels " << curve << " (" << curve_inside << " inside), marker pixels "
                       << marker);
      CHECK(coverage > (view == View::Top ? 0.9 : 0.45));
      CHECK(coverage <= 1.0);
      // Curves are visible over the surface, not only along its border.
      CHECK(curve > kWidth * kHeight / 100);
      CHECK(curve_inside > 150);
      CHECK(marker >= 10);
    }
  }
}

TEST_CASE("a pending piece of a stroke is drawn in the stroke's colour, not as a curve", "[render][chain]") {
  auto context = make_context();
  auto renderer = Renderer::create(*context, {kWidth, kHeight});
  REQUIRE(renderer);
  Scene scene = demo_scene();
  auto stroke_pixels = [&](const Image& image) {
    size_t n = 0;
    for (uint32_t y = 0; y < kHeight; ++y)
      for (uint32_t x = 0; x < kWidth; ++x) n += near(image.pixel(x, y), Palette::stroke, 30);
    return n;
  };
  CHECK(stroke_pixels(render_scene(*context, **renderer, scene, View::Top)) == 0);
  // From the middle of a curve a fifth of the object's width outwards, as a stroke that ended off the network.
  Mesh& net = scene.network;
  EdgeIndex curve{0};
  while (!net.edge_alive(curve) || net.edges.point_count[curve] < 3) ++curve;
  const Box box = box_of(scene);
  const Vec3 from = net.polyline(curve)[net.edges.point_count[curve] / 2];
  const Vec3 to = from + Vec3(0.2 * double(box.hi.x - box.lo.x), 0, 0);
  std::vector<Vec3> piece;
  for (int k = 0; k <= 8; ++k) piece.push_back(from + (to - from) * (k / 8.0));
  piece.back() = to;
  net.begin_frame(net.frame() + 1);
  const EdgeIndex e = net.add_edge(net.add_vertex(from), net.add_vertex(to), piece);
  net.set_edge_flag(e, kPendingEdge, true);
  REQUIRE(net.validate() == "");
  const Image image = render_scene(*context, **renderer, scene, View::Top);
  const size_t pending = stroke_pixels(image);
  INFO("pixels in the stroke's colour " << pending);
  CHECK(pending > 30);
  // FIRE_RENDER_OUT=DIR writes the image there, to look at.
  if (const char* out = std::getenv("FIRE_RENDER_OUT")) REQUIRE(write_png(image, std::string(out) + "/pending_top.png"));
}

TEST_CASE("uploads copy only what changed and the image equals a fresh upload's") {
  auto context = make_context();
  auto incremental = Renderer::create(*context, {kWidth, kHeight});
  REQUIRE(incremental);
  Renderer& r = **incremental;
  Scene scene = demo_scene();
  Mesh& net = scene.network;

  uint64_t points = 0, vertices = 0;
  for (EdgeIndex e{0}; e < net.edge_slots(); ++e)
    if (net.edge_alive(e)) points += net.edges.point_count[e];
  for (VertexIndex v{0}; v < net.vertex_slots(); ++v) vertices += net.vertex_alive(v);
  REQUIRE(r.upload(net, scene.surface));
  CHECK(r.last_upload().bytes ==
        12 * (points + vertices) + 24ull * scene.surface.vertex_count() + 24ull * scene.surface.quad_count());
  CHECK(r.last_upload().edges == net.edge_count());
  CHECK(r.last_upload().surface_quads == scene.surface.quad_count());

  net.begin_frame(net.frame() + 1);
  REQUIRE(r.upload(net, scene.surface));
  CHECK(r.last_upload().bytes == 0);

  // Moving one vertex re-sends the points of its edges and its marker, nothing else.
  VertexIndex moved{0};
  while (!net.vertex_alive(moved) || net.valence(moved) < 3) ++moved;
  uint64_t edge_points = 0;
  for (EdgeIndex e : net.vertex_edges(moved)) edge_points += net.edges.point_count[e];
  net.begin_frame(net.frame() + 1);  // an edit belongs to a frame after the last upload's
  net.move_vertex(moved, net.vertices.position[moved] + Vec3(0, 0, 0.01));
  REQUIRE(r.upload(net, scene.surface));
  CHECK(r.last_upload().edges == net.valence(moved));
  CHECK(r.last_upload().vertices == 1);
  CHECK(r.last_upload().bytes == 12 * (edge_points + 1));
  net.begin_frame(net.frame() + 1);

  // A surface write of a vertex range re-sends that range only.
  for (uint32_t v = 100; v < 140; ++v) scene.surface.positions[v].z() += 0.002;
  scene.surface.frame = 2;
  scene.surface.changed = {100, 140};
  REQUIRE(r.upload(net, scene.surface));
  CHECK(r.last_upload().bytes == 40 * 24);
  CHECK(r.last_upload().surface_quads == 0);
  // The same frame again: nothing new.
  REQUIRE(r.upload(net, scene.surface));
  CHECK(r.last_upload().bytes == 0);

  // A new topology version with the same quads and values: the block is kept, nothing is copied.
  ++scene.surface.topology_version;
  scene.surface.frame = 3;
  scene.surface.changed = {0, scene.surface.vertex_count()};
  REQUIRE(r.upload(net, scene.surface));
  CHECK(r.last_upload().bytes == 0);

  // The quads in patches of 64: each patch gets its block, its triangles copied once.
  const uint32_t quads = scene.surface.quad_count();
  for (uint32_t q = 0, key = 0; q < quads; q += 64, ++key) {
    scene.surface.patch_offsets.push_back(q);
    scene.surface.patch_keys.push_back(key);
  }
  scene.surface.patch_offsets.push_back(quads);
  REQUIRE(scene.surface.patch_count() >= 4);
  ++scene.surface.topology_version;
  scene.surface.frame = 4;
  REQUIRE(r.upload(net, scene.surface));
  CHECK(r.last_upload().surface_quads == quads);
  // One quad of patch 2 starts at another corner (its diagonal flips): patch 2's triangles are copied
  // into the block it frees, the same vertices in the same place, so no vertex is.
  uint32_t* quad = &scene.surface.quads[4 * size_t(scene.surface.patch_offsets[2] + 5)];
  std::rotate(quad, quad + 1, quad + 4);
  ++scene.surface.topology_version;
  scene.surface.frame = 5;
  REQUIRE(r.upload(net, scene.surface));
  CHECK(r.last_upload().surface_quads == 64);
  CHECK(r.last_upload().surface_vertices == 0);
  CHECK(r.last_upload().bytes == 64 * 24);
  // Moving one surface vertex copies it once per patch that holds it (one to four).
  const uint32_t v = scene.surface.quads[4 * size_t(scene.surface.patch_offsets[3])];
  scene.surface.positions[v].z() += 0.003;
  scene.surface.frame = 6;
  scene.surface.changed = {v, v + 1};
  REQUIRE(r.upload(net, scene.surface));
  CHECK(r.last_upload().surface_vertices >= 1);
  CHECK(r.last_upload().surface_vertices <= 4);
  CHECK(r.last_upload().bytes == 24ull * r.last_upload().surface_vertices);

  const Camera camera = frame_box(box_of(scene), View::Iso, kWidth, kHeight);
  REQUIRE(r.draw(camera));
  const Image after_edits = r.image();
  auto fresh = Renderer::create(*context, {kWidth, kHeight});
  REQUIRE(fresh);
  REQUIRE((*fresh)->upload(net, scene.surface));
  REQUIRE((*fresh)->draw(camera));
  CHECK(after_edits.rgba == (*fresh)->image().rgba);
  CHECK(context->validation_message_count() == 0);
}

TEST_CASE("samples per pixel: by device, by setting or by FIRE_SAMPLES, 4x draws the scene 1x draws") {
  auto context = make_context();
  const char* saved = std::getenv("FIRE_SAMPLES");
  const std::string restore = saved ? saved : "";
  unsetenv("FIRE_SAMPLES");
  auto by_device = Renderer::create(*context, {kWidth, kHeight});
  REQUIRE(by_device);
  const bool cpu = context->properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  CHECK((*by_device)->samples() == (cpu ? VK_SAMPLE_COUNT_1_BIT : VK_SAMPLE_COUNT_4_BIT));
  auto four = Renderer::create(*context, {kWidth, kHeight, 4});  // every device has 4x (Vulkan requires it)
  REQUIRE(four);
  CHECK((*four)->samples() == VK_SAMPLE_COUNT_4_BIT);
  CHECK_FALSE(Renderer::create(*context, {kWidth, kHeight, 3}));
  setenv("FIRE_SAMPLES", "4", 1);
  auto from_env = Renderer::create(*context, {kWidth, kHeight});
  REQUIRE(from_env);
  CHECK((*from_env)->samples() == VK_SAMPLE_COUNT_4_BIT);
  setenv("FIRE_SAMPLES", "many", 1);
  auto bad = Renderer::create(*context, {kWidth, kHeight});
  REQUIRE_FALSE(bad);
  CHECK(bad.error().find("FIRE_SAMPLES") != std::string::npos);
  if (saved) setenv("FIRE_SAMPLES", restore.c_str(), 1);
  else unsetenv("FIRE_SAMPLES");

  // The multisampled target resolves to the single-sampled image but for the edges: the same scene.
  Scene scene = demo_scene();
  RenderSettings one_sample{kWidth, kHeight, 1};
  auto one = Renderer::create(*context, one_sample);
  REQUIRE(one);
  const Image a = render_scene(*context, **one, scene, View::Iso), b = render_scene(*context, **four, scene, View::Iso);
  const size_t differing = pixels_differing(a, b);
  INFO(differing << " of " << a.rgba.size() / 4 << " pixels differ by more than 48 in a channel");
  CHECK(differing < a.rgba.size() / 4 / 25);  // 2.2 % on lavapipe, 320 x 180: the curves' and markers' edges
  CHECK(a.rgba != b.rgba);  // the edges are smoothed: 4x did run
}

TEST_CASE("drawn in a window's B8G8R8A8_SRGB, the image reads back as the RGBA one") {
  auto context = make_context();
  const Scene scene = demo_scene();
  auto rgba = Renderer::create(*context, {kWidth, kHeight, 1, VK_FORMAT_R8G8B8A8_SRGB});
  auto bgra = Renderer::create(*context, {kWidth, kHeight, 1, VK_FORMAT_B8G8R8A8_SRGB});
  REQUIRE(rgba);
  REQUIRE(bgra);
  CHECK(render_scene(*context, **bgra, scene, View::Iso).rgba == render_scene(*context, **rgba, scene, View::Iso).rgba);
  CHECK_FALSE(Renderer::create(*context, {kWidth, kHeight, 1, VK_FORMAT_R8G8B8A8_UNORM}));
}

TEST_CASE("a provisional surface is tinted, a settled one is neutral grey") {
  auto context = make_context();
  auto renderer = Renderer::create(*context, {kWidth, kHeight});
  REQUIRE(renderer);
  Scene scene = demo_scene();
  scene.network = Mesh{};  // the surface alone
  auto mean_tint = [&](bool settled) {
    scene.surface.settled = settled;
    const Image image = render_scene(*context, **renderer, scene, View::Top);
    double blue_minus_red = 0;
    size_t n = 0;
    for (uint32_t y = 0; y < kHeight; ++y)
      for (uint32_t x = 0; x < kWidth; ++x)
        if (!is_background(image, x, y)) {
          blue_minus_red += int(image.pixel(x, y)[2]) - int(image.pixel(x, y)[0]);
          ++n;
        }
    REQUIRE(n > kWidth * kHeight / 4);
    return blue_minus_red / double(n);
  };
  const double settled = mean_tint(true), provisional = mean_tint(false);
  INFO("settled " << settled << ", provisional " << provisional);
  CHECK(std::abs(settled) < 15);
  CHECK(provisional > settled + 25);
}

TEST_CASE("the pen's feedback: the face under the pen tinted, the snap target and the closing vertex marked") {
  auto context = make_context();
  auto renderer = Renderer::create(*context, {kWidth, kHeight});
  REQUIRE(renderer);
  Renderer& r = **renderer;
  Scene scene = demo_scene();
  const Camera camera = frame_box(box_of(scene), View::Top, kWidth, kHeight);
  auto draw = [&](const Mesh& network, const PenFeedback& feedback) {
    REQUIRE(r.upload(network, scene.surface));
    REQUIRE(r.set_pen_feedback(network, feedback));
    REQUIRE(r.draw(camera));
    CHECK(context->validation_message_count() == 0);
    return r.image();
  };
  auto pixel_at = [&](const Image& im, const Vec3& p) {
    const glm::vec2 px = project_to_pixels(camera, p, kWidth, kHeight);
    return im.pixel(uint32_t(px.x), uint32_t(px.y));
  };
  const Mesh& net = scene.network;
  FaceIndex face{0};
  while (!net.face_alive(face)) ++face;
  const Vec3 centre = loop_plane(net.face_boundary(face)).centroid;
  const EdgeIndex edge = edge_of(net.face_loop(face)[0]);
  const uint32_t point = net.edges.point_count[edge] / 2;

  const Image plain = draw(net, {});
  PenFeedback feedback;
  feedback.pen_seen = true;
  feedback.face = net.face_id(face);
  feedback.target_edge = net.edge_id(edge);
  feedback.target_point = point;
  feedback.target = net.polyline(edge)[point];
  const Image shown = draw(net, feedback);
  {  // the face's middle turns magenta: red and blue over green, where the plain surface is grey
    const uint8_t* before = pixel_at(plain, centre);
    const uint8_t* after = pixel_at(shown, centre);
    INFO("face centre before " << int(before[0]) << "," << int(before[1]) << "," << int(before[2]) << " after "
                               << int(after[0]) << "," << int(after[1]) << "," << int(after[2]));
    CHECK(std::abs(int(before[0]) - int(before[1])) < 20);
    CHECK(int(after[0]) - int(after[1]) > 30);
    CHECK(int(after[2]) - int(after[1]) > 20);
  }
  CHECK(near(pixel_at(shown, feedback.target), Palette::snap_target, 30));
  CHECK_FALSE(near(pixel_at(plain, feedback.target), Palette::snap_target, 30));
  PenFeedback moved = feedback;  // the pen along the same curve: only the marker is copied again
  moved.target = net.polyline(edge)[point - 1];
  draw(net, moved);
  CHECK(r.last_upload().bytes == sizeof(glm::vec3));

  PenFeedback stale = feedback;  // handles whose generation moved on are not drawn
  ++stale.face.generation;
  ++stale.target_edge.generation;
  const Image none = draw(net, stale);
  CHECK(std::equal(none.rgba.begin(), none.rgba.end(), plain.rgba.begin(), plain.rgba.end()));

  // Border mode: an open border of two curves, the pen by its first vertex.
  Mesh border;
  const Vec3 a = net.vertices.position[net.edges.vertex[edge][0]], b = net.vertices.position[net.edges.vertex[edge][1]];
  const VertexIndex va = border.add_vertex(a), vb = border.add_vertex(b), vc = border.add_vertex(centre);
  border.add_edge(va, vb, std::vector<Vec3>{a, b});
  border.add_edge(vb, vc, std::vector<Vec3>{b, centre});
  PenFeedback closing;
  closing.pen_seen = true;
  closing.first_vertex = border.vertex_id(va);
  closing.closes_border = true;
  closing.target = a;
  CHECK(near(pixel_at(draw(border, closing), a), Palette::close_border, 30));
  closing.closes_border = false;  // too far to close: the first vertex is not marked
  CHECK_FALSE(near(pixel_at(draw(border, closing), a), Palette::close_border, 30));
}

TEST_CASE("a still frame is not drawn again: its layer is copied and the stroke drawn over it, with a whole frame's pixels",
          "[render][still]") {
  auto context = make_context();
  auto renderer = Renderer::create(*context, {kWidth, kHeight});
  REQUIRE(renderer);
  Renderer& r = **renderer;
  Scene scene = demo_scene();
  const Camera camera = frame_box(box_of(scene), View::Iso, kWidth, kHeight);
  const Camera elsewhere = frame_box(box_of(scene), View::Top, kWidth, kHeight);
  const Mesh& net = scene.network;
  FaceIndex face{0};
  while (!net.face_alive(face)) ++face;
  const EdgeIndex edge = edge_of(net.face_loop(face)[0]);
  PenFeedback feedback;
  feedback.pen_seen = true;
  feedback.face = net.face_id(face);
  feedback.target_edge = net.edge_id(edge);
  feedback.target_point = net.edges.point_count[edge] / 2;
  feedback.target = net.polyline(edge)[feedback.target_point];
  const std::vector<Vec3> marks{net.vertices.position[net.edges.vertex[edge][0]]};
  std::vector<Vec3> stroke{net.polyline(edge).begin(), net.polyline(edge).end()};
  auto draw = [&](const Camera& c) {
    REQUIRE(r.upload(scene.network, scene.surface));
    REQUIRE(r.set_stroke(stroke));
    REQUIRE(r.set_pen_feedback(scene.network, feedback));
    REQUIRE(r.set_marks(marks, 0));
    REQUIRE(r.draw(c));
    CHECK(context->validation_message_count() == 0);
    return r.image();
  };
  auto same = [](const Image& a, const Image& b) { return a.rgba == b.rgba; };

  const Image whole = draw(camera);
  CHECK(r.layer_frames() == 0);
  const Image first_still = draw(camera);  // the layer drawn, then copied
  CHECK(r.layer_frames() == 1);
  const Image second_still = draw(camera);  // copied
  CHECK(r.layer_frames() == 2);
  CHECK(same(whole, first_still));
  CHECK(same(whole, second_still));

  // The stroke, the pen's feedback and the marks are drawn over the layer: a new stroke keeps the frame still.
  stroke.resize(stroke.size() / 2);
  feedback.target_point = 1;
  feedback.target = net.polyline(edge)[1];
  const Image shorter = draw(camera);
  CHECK(r.layer_frames() == 3);
  CHECK_FALSE(same(shorter, whole));
  draw(elsewhere);
  CHECK(r.layer_frames() == 0);
  CHECK(same(draw(camera), shorter));  // drawn whole again: the still frame had its pixels
  CHECK(r.layer_frames() == 0);

  // What upload() changes is drawn whole: a settled surface turned provisional.
  draw(camera);
  CHECK(r.layer_frames() == 1);
  scene.surface.settled = !scene.surface.settled;
  const Image tinted = draw(camera);
  CHECK(r.layer_frames() == 0);
  CHECK_FALSE(same(tinted, shorter));
  CHECK(same(draw(camera), tinted));
  CHECK(r.layer_frames() == 1);
  // So is a reference mesh shown: a triangle across the box's top, above the surface.
  const Box box = box_of(scene);
  const Vec3 lo(box.lo.x, box.lo.y, box.hi.z), hi(box.hi.x, box.hi.y, box.hi.z);
  const std::vector<Vec3> triangle{lo, Vec3(hi.x(), lo.y(), hi.z()), hi};
  REQUIRE(r.set_reference(triangle, std::vector<uint32_t>{0, 1, 2}));
  const Image with_reference = draw(camera);
  CHECK(r.layer_frames() == 0);
  CHECK_FALSE(same(with_reference, tinted));
}

TEST_CASE("while the camera moves the surface is drawn coarser, by its quads' size on screen, and a still frame whole",
          "[render][coarser]") {
  auto context = make_context();
  Scene scene = demo_scene();
  scene.surface.level = reconstruct::Options{}.levels;  // what reconstruct_surface refined, as the subdivide system says it
  REQUIRE(scene.surface.level >= 2);
  auto drawn = [&](Renderer& r, const Camera& c) {
    REQUIRE(r.upload(scene.network, scene.surface));
    REQUIRE(r.draw(c));
    CHECK(context->validation_message_count() == 0);
    return r.image();
  };
  const Box box = box_of(scene);
  // From the framed view to one three times as far, where the surface's quads are a few pixels across.
  Orbit orbit = frame_orbit(box, kWidth, kHeight);
  const Camera camera = orbit_camera(orbit, kWidth, kHeight);
  orbit.distance *= 3;
  orbit.rotate(40, 0);
  const Camera elsewhere = orbit_camera(orbit, kWidth, kHeight);
  orbit.rotate(40, 0);
  const Camera beside = orbit_camera(orbit, kWidth, kHeight);  // as far: as many levels dropped

  auto whole_renderer = Renderer::create(*context, {kWidth, kHeight});
  REQUIRE(whole_renderer);
  drawn(**whole_renderer, camera);
  const Image whole = drawn(**whole_renderer, elsewhere);
  CHECK((*whole_renderer)->coarser_levels() == 0);  // off unless asked for: headless renders draw every level

  auto renderer = Renderer::create(*context, {kWidth, kHeight, 0, VK_FORMAT_R8G8B8A8_SRGB, true});
  REQUIRE(renderer);
  Renderer& r = **renderer;
  drawn(r, camera);
  CHECK(r.coarser_levels() == 0);  // a first frame did not move
  const Image moving = drawn(r, elsewhere);
  const uint32_t step = r.coarser_levels();
  INFO("levels dropped " << step << " of " << scene.surface.level << ", quads " << scene.surface.quad_count());
  REQUIRE(step >= 1);
  REQUIRE(step < scene.surface.level);
  // Its triangles were built for this frame: a quarter of the quads per level, 6 indices each.
  CHECK(r.last_upload().bytes == uint64_t(scene.surface.quad_count() >> (2 * step)) * 6 * sizeof(uint32_t));
  // A coarser limit mesh of the same surface: not the same pixels, but within a pixel or two along its outline.
  const size_t differing = pixels_differing(moving, whole);
  CHECK(moving.rgba != whole.rgba);
  CHECK(differing < moving.rgba.size() / 4 / 50);
  // The camera stops: drawn whole, the pixels of a renderer that never draws coarser.
  CHECK(drawn(r, elsewhere).rgba == whole.rgba);
  CHECK(r.coarser_levels() == 0);
  // Moving on at that distance draws the triangles built before.
  drawn(r, beside);
  CHECK(r.coarser_levels() == step);
  CHECK(r.last_upload().bytes == 0);
  // Closer, the quads are larger on screen and fewer levels are dropped.
  auto big = Renderer::create(*context, {1280, 720, 0, VK_FORMAT_R8G8B8A8_SRGB, true});
  REQUIRE(big);
  Orbit big_orbit = frame_orbit(box, 1280, 720);
  drawn(**big, orbit_camera(big_orbit, 1280, 720));
  big_orbit.distance *= 4;
  drawn(**big, orbit_camera(big_orbit, 1280, 720));
  const uint32_t far_step = (*big)->coarser_levels();
  big_orbit.distance /= 16;
  drawn(**big, orbit_camera(big_orbit, 1280, 720));
  const uint32_t near_step = (*big)->coarser_levels();
  INFO("levels dropped far away " << far_step << ", close up " << near_step);
  CHECK(far_step > near_step);
}

TEST_CASE("Vulkan failures name the call") {
  CHECK(vk_failure("vkCreateDevice(physical_, &device, nullptr, &device_)", VK_ERROR_DEVICE_LOST) ==
        "vkCreateDevice failed: VK_ERROR_DEVICE_LOST (-4)");
  CHECK_FALSE(parse_view("diagonal"));
  CHECK(parse_view("side"));
  CHECK(parse_view("bottom"));
}

TEST_CASE("framing keeps every corner of the box inside the image") {
  Box box;
  box.add(Vec3(-1, -2, 0));
  box.add(Vec3(3, 1, 0.5));
  for (View view : {View::Iso, View::Front, View::Top, View::Side, View::Bottom}) {
    const Camera camera = frame_box(box, view, 640, 360);
    for (int c = 0; c < 8; ++c) {
      const Vec3 p((c & 1) ? 3 : -1, (c & 2) ? 1 : -2, (c & 4) ? 0.5 : 0);
      const glm::vec2 q = project_to_pixels(camera, p, 640, 360);
      CHECK(q.x >= 0);
      CHECK(q.x <= 640);
      CHECK(q.y >= 0);
      CHECK(q.y <= 360);
    }
  }
  // Top and bottom look from above and from below.
  CHECK(frame_box(box, View::Top, 640, 360).eye.z > 0.5f);
  CHECK(frame_box(box, View::Bottom, 640, 360).eye.z < 0.0f);
}

TEST_CASE("the app's orbit camera: a ray through a pixel lands on it, pixel sizes, pan, zoom and pitch") {
  Box box;
  box.add(Vec3(-1, -0.5, 0));
  box.add(Vec3(1, 0.5, 2));
  Orbit orbit = frame_orbit(box, 800, 500);
  orbit.rotate(37, -21);
  orbit.zoom(1.5f);
  const Camera camera = orbit_camera(orbit, 800, 500);
  for (const glm::vec2 pixel : {glm::vec2(0, 0), glm::vec2(400, 250), glm::vec2(799, 13), glm::vec2(123.5f, 480)}) {
    const glm::vec3 direction = ray_through_pixel(camera, pixel, 800, 500);
    CHECK(glm::length(direction) == Approx(1.0f).epsilon(1e-5));
    const glm::vec3 p = camera.eye + 3.0f * direction;
    const glm::vec2 back = project_to_pixels(camera, Vec3(p.x, p.y, p.z), 800, 500);
    CHECK(glm::length(back - pixel) < 0.01f);
    // One pixel_size_at along the camera's right axis (square to the view axis) is one pixel on screen.
    const glm::vec3 side(camera.view[0][0], camera.view[1][0], camera.view[2][0]);
    const glm::vec3 q = p + pixel_size_at(camera, p, 500) * side;
    const float moved = glm::length(project_to_pixels(camera, Vec3(q.x, q.y, q.z), 800, 500) - back);
    CHECK(moved == Approx(1.0f).epsilon(1e-3));
  }
  // Panning moves the target by the pixels' model length at its depth, whatever the zoom.
  const glm::vec3 before = orbit.target;
  orbit.pan(10, 0, 500);
  const glm::vec2 a = project_to_pixels(camera, Vec3(before.x, before.y, before.z), 800, 500);
  const glm::vec2 b = project_to_pixels(camera, Vec3(orbit.target.x, orbit.target.y, orbit.target.z), 800, 500);
  CHECK(glm::length(b - a) == Approx(10.0f).epsilon(0.02));
  const float distance = orbit.distance;
  orbit.zoom(-2);
  CHECK(orbit.distance > distance);
  orbit.rotate(0, 10000);
  CHECK(orbit.pitch < 1.56f);  // never over the pole
}

TEST_CASE("validation messages are counted, so the tests above would fail on one") {
  auto context = make_context();
  VkBufferCreateInfo invalid{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  invalid.size = 0;  // must be greater than 0: the layer reports it
  invalid.usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT;
  VkBuffer buffer = VK_NULL_HANDLE;
  const VkResult result = vkCreateBuffer(context->device(), &invalid, nullptr, &buffer);
  if (result == VK_SUCCESS) vkDestroyBuffer(context->device(), buffer, nullptr);
  CHECK(context->validation_message_count() >= 1);
}
