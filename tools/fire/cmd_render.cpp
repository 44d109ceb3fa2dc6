// fire render: a curve network (or the network an input log draws) and its reconstructed surface,
// rendered headless with Vulkan (lavapipe without a GPU) into a PNG.
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "engine/input_log.hpp"
#include "platform/clock.hpp"
#include "platform/network_file.hpp"
#include "platform/obj.hpp"
#include "platform/render/renderer.hpp"
#include "systems/reconstruct/reconstruct.hpp"
#include "tools/fire/commands.hpp"
#include "tools/fire/session.hpp"

namespace fire::cli {

namespace {

struct RenderArgs {
  std::string input_path, out_path, size = "1280x720", view = "iso", reference_path;
  uint32_t levels = 3;
};

int fail(const std::string& message) {
  std::cerr << "fire render: " << message << "\n";
  return 1;
}

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// The network of a .fnet file, or the one an input log draws when replayed headless.
Result<Mesh> load_input(const std::string& path) {
  if (ends_with(path, ".fnet")) return load_network(path);
  auto log = read_input_log(path);
  if (!log) return Result<Mesh>::failure(log.error());
  auto world = std::make_unique<World>();
  world->log = std::move(*log);
  Scheduler scheduler = make_scheduler(*world, monotonic_ns);
  replay_headless(*world, scheduler);
  for (const Rejection& r : world->rejections) std::cerr << path << ":" << r.line << ": rejected: " << r.reason << "\n";
  if (std::string problem = world->mesh.validate(); !problem.empty())
    return Result<Mesh>::failure(path + ": the replayed network is invalid: " + problem);
  return std::move(world->mesh);
}

int run_render(const RenderArgs& a) {
  uint32_t width = 0, height = 0;
  char tail = 0;
  if (std::sscanf(a.size.c_str(), "%ux%u%c", &width, &height, &tail) != 2 || width == 0 || height == 0 ||
      width > 8192 || height > 8192)
    return fail("--size must be WIDTHxHEIGHT, 1 to 8192 pixels a side, not '" + a.size + "'");
  auto view = render::parse_view(a.view);
  if (!view) return fail(view.error());
  if (!ends_with(a.out_path, ".png")) return fail(a.out_path + ": the output must be a .png file");
  if (a.levels < 1 || a.levels > reconstruct::kMaxLevels)
    return fail("--levels must be 1 to " + std::to_string(reconstruct::kMaxLevels));

  // The reference's triangles (faces as fans), read before anything expensive.
  std::vector<Vec3> reference_positions;
  std::vector<uint32_t> reference_triangles;
  if (!a.reference_path.empty()) {
    auto mesh = read_obj(a.reference_path);
    if (!mesh) return fail("--reference: " + mesh.error());
    reference_positions = mesh->positions;
    for (size_t f = 0; f < mesh->face_count(); ++f) {
      const uint32_t* v = &mesh->face_vertices[mesh->face_offsets[f]];
      for (uint32_t k = 1; k + 1 < mesh->face_size(f); ++k)
        reference_triangles.insert(reference_triangles.end(), {v[0], v[k], v[k + 1]});
    }
  }

  auto network = load_input(a.input_path);
  if (!network) return fail(network.error());
  reconstruct::Options options;
  options.levels = a.levels;
  SurfaceLevels surface;
  auto built = reconstruct::reconstruct_surface(*network, options);
  if (!built) std::cerr << "fire render: no surface, drawing the curves only: " << built.error() << "\n";
  else if (!assign_quads(*built, 1, surface)) return fail("internal error: the reconstructed surface is not all quads");
  surface.level = a.levels;

  render::Box box;
  for (uint32_t e = 0; e < network->edge_slots(); ++e)
    if (network->edge_alive(e))
      for (const Vec3& p : network->polyline(e)) box.add(p);
  for (const Vec3& p : surface.positions) box.add(p);
  for (const Vec3& p : reference_positions) box.add(p);
  if (box.empty()) return fail(a.input_path + ": nothing to draw (no curves)");

  auto context = render::Context::create();
  if (!context) return fail(context.error());
  auto renderer = render::Renderer::create(**context, {width, height});
  if (!renderer) return fail(renderer.error());
  Status drawn = (*renderer)->set_reference(reference_positions, reference_triangles);
  if (drawn) drawn = (*renderer)->upload(*network, surface);
  if (drawn) drawn = (*renderer)->draw(render::frame_box(box, *view, width, height));
  if (!drawn) return fail("Vulkan: " + drawn.error);
  const uint64_t bytes = (*renderer)->last_upload().bytes;
  const std::string device = (*context)->device_name();
  const size_t messages = (*context)->validation_message_count();
  const bool validation = (*context)->validation();
  const render::Image image = (*renderer)->image();
  renderer->reset();
  context->reset();  // the layer may still report while the device and instance are destroyed
  if (validation && messages) return fail(std::to_string(messages) + " Vulkan validation message(s), see above");
  if (Status written = render::write_png(image, a.out_path); !written) return fail(written.error);

  nlohmann::ordered_json out;
  out["output"] = a.out_path;
  out["width"] = width;
  out["height"] = height;
  out["view"] = a.view;
  out["device"] = device;
  out["edges"] = network->edge_count();
  out["surface_quads"] = surface.quad_count();
  out["bytes_uploaded"] = bytes;
  out["validation"] = validation;
  std::cout << out.dump() << "\n";
  return 0;
}

}  // namespace

void add_render_commands(CLI::App& app, Registry& registry) {
  auto a = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "Render a curve network and its surface to a PNG, headless");
  cmd->footer(
      "NET is a curve network (.fnet, engine/NETWORK_FORMAT.md); any other file is read as an input log and "
      "replayed headless first. The network is reconstructed (the fire method) and drawn with Vulkan, offscreen: "
      "the lit surface, the curves over it, the vertices as markers, the reference mesh see-through. Without a "
      "GPU, Vulkan runs on lavapipe (Debian package mesa-vulkan-drivers). FIRE_VK_VALIDATION=1 turns the "
      "validation layer on; any message then fails the command. Prints one JSON line: output, width, height, "
      "view, device, edges, surface_quads, bytes_uploaded, validation.");
  cmd->add_option("NET", a->input_path, "curve network (.fnet) or input log")->required();
  cmd->add_option("-o,--output", a->out_path, "PNG file to write")->required();
  cmd->add_option("--size", a->size, "WIDTHxHEIGHT in pixels")->capture_default_str();
  cmd->add_option("--view", a->view, "iso, front, top or side (Z up)")->capture_default_str();
  cmd->add_option("--reference", a->reference_path, "OBJ mesh drawn see-through over the scene");
  cmd->add_option("--levels", a->levels, "Catmull-Clark levels of the surface (1 to 6)")->capture_default_str();
  cmd->callback([a, &registry] { registry.exit_code = run_render(*a); });
}

}  // namespace fire::cli
