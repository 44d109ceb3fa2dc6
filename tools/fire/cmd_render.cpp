// fire render: a curve network (or the network an input log draws) and its reconstructed surface,
// rendered headless with Vulkan (lavapipe without a GPU) into a PNG.
#include <algorithm>
#include <cstdio>
#include <filesystem>
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
#include "tools/fire/surface_args.hpp"
#include "tools/app/session.hpp"
#include "tools/app/session_rig.hpp"

namespace fire::cli {

namespace {

struct RenderArgs {
  std::string input_path, out_path, size = "1280x720", view = "iso", reference_path, png_dir, rig_path;
  uint32_t every = 0;
  SurfaceArgs surface;
};

int fail(const std::string& message) {
  std::cerr << "fire render: " << message << "\n";
  return 1;
}

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// An input log ready to replay: with the rig of --rig when its Wii Remote reports are to be triangulated.
Result<std::unique_ptr<World>> world_for_log(const std::string& path, const std::string& rig_path) {
  using R = Result<std::unique_ptr<World>>;
  auto log = read_input_log(path);
  if (!log) return R::failure(log.error());
  auto world = std::make_unique<World>();
  if (!rig_path.empty()) {
    Result<TrackingRig> rig = load_tracking_rig(rig_path, *log, path);
    if (!rig) return R::failure(rig.error());
    set_rig(*world, *rig);
  } else if (has_device_reports(*log)) {
    return R::failure(path + " holds Wii Remote reports; give the rig they were drawn with: --rig RIG.json (from fire calibrate)");
  }
  world->log = std::move(*log);
  return world;
}

// The network of a .fnet file, or the one an input log draws when replayed headless. Without the surface
// systems: the surface is reconstructed from the network afterwards (and --every replays with them).
Result<Mesh> load_input(const std::string& path, const std::string& rig_path) {
  if (ends_with(path, ".fnet")) return load_network(path);
  auto loaded = world_for_log(path, rig_path);
  if (!loaded) return Result<Mesh>::failure(loaded.error());
  std::unique_ptr<World> world = std::move(*loaded);
  world->build_surface = false;
  Scheduler scheduler = make_scheduler(*world, monotonic_ns);
  replay_headless(*world, scheduler);
  for (const Rejection& r : world->rejections) std::cerr << path << ":" << r.line << ": rejected: " << r.reason << "\n";
  if (std::string problem = world->mesh.validate(); !problem.empty())
    return Result<Mesh>::failure(path + ": the replayed network is invalid: " + problem);
  return std::move(world->mesh);
}

// --every N: the input log replayed with the renderer as the frame's last system. Every frame at least N
// frames after the previous picture whose network changed is reconstructed incrementally, uploaded by
// changed range and written to DIR/frame_NNNNNN.png; one JSON line per picture says what was uploaded.
// The camera frames the final network, so the pictures line up.
int render_sequence(const RenderArgs& a, const reconstruct::Options& options, const Mesh& final_network,
                    render::Renderer& renderer, const render::Camera& camera) {
  std::error_code error;
  std::filesystem::create_directories(a.png_dir, error);
  if (error) return fail(a.png_dir + ": cannot create the directory (" + error.message() + ")");
  auto loaded = world_for_log(a.input_path, a.rig_path);
  if (!loaded) return fail(loaded.error());
  std::unique_ptr<World> world = std::move(*loaded);
  world->surface_options = options;

  Status status;
  uint64_t last_picture = 0;
  bool pictured = false;
  // The frame's own surface (refine and subdivide ran before), uploaded by what changed since the last picture.
  auto picture = [&](bool last) {
    World& w = *world;
    if (!status || w.mesh.edge_count() == 0) return;
    const bool changed = !pictured || w.mesh.written_after(last_picture) || w.surface.frame > last_picture;
    if (!changed || (pictured && w.frame.index < last_picture + a.every && !last)) return;
    status = renderer.upload(w.mesh, w.surface);
    if (status) status = renderer.draw(camera);
    if (!status) return;
    char name[32];
    std::snprintf(name, sizeof name, "frame_%06llu.png", static_cast<unsigned long long>(w.frame.index));
    const std::string path = (std::filesystem::path(a.png_dir) / name).string();
    status = render::write_png(renderer.image(), path);
    if (!status) return;
    const render::UploadStats& u = renderer.last_upload();
    nlohmann::ordered_json out;
    out["frame"] = w.frame.index;
    out["png"] = path;
    out["edges"] = w.mesh.edge_count();
    out["surface_quads"] = w.surface.quad_count();
    out["bytes_uploaded"] = u.bytes;
    out["edges_uploaded"] = u.edges;
    out["surface_vertices_uploaded"] = u.surface_vertices;
    std::cout << out.dump() << "\n";
    last_picture = w.frame.index;
    pictured = true;
  };
  std::vector<SystemSpec> systems = session_systems(*world);
  // The renderer, last in the frame: it reads what the picture shows (the picture's own state is outside the world).
  systems.push_back(declare_system<Read<&World::frame>, Read<&World::mesh>, Read<&World::surface>>(
      *world, "render", picture,
      [](decltype(picture)& draw, const FrameTime&, const Mesh&, const SurfaceLevels&) { draw(false); }));
  auto scheduler = Scheduler::build(std::move(systems), monotonic_ns);
  if (!scheduler) return fail("internal error: " + scheduler.error());
  replay_headless(*world, *scheduler);
  picture(true);
  if (!status) return fail(status.error);
  if (!pictured) return fail(a.input_path + ": the replay drew nothing");
  if (final_network.hash() != world->mesh.hash()) return fail("internal error: the replay with pictures differs from the replay without");
  return 0;
}

int run_render(const RenderArgs& a, const CLI::App& cmd) {
  uint32_t width = 0, height = 0;
  char tail = 0;
  if (std::sscanf(a.size.c_str(), "%ux%u%c", &width, &height, &tail) != 2 || width == 0 || height == 0 ||
      width > 8192 || height > 8192)
    return fail("--size must be WIDTHxHEIGHT, 1 to 8192 pixels a side, not '" + a.size + "'");
  auto view = render::parse_view(a.view);
  if (!view) return fail(view.error());
  if (a.out_path.empty() == (a.every == 0)) return fail("give either -o OUT.png or --every N with --png-dir DIR");
  if (a.every && (a.png_dir.empty() || ends_with(a.input_path, ".fnet")))
    return fail("--every needs an input log and --png-dir DIR");
  if (!a.every && !ends_with(a.out_path, ".png")) return fail(a.out_path + ": the output must be a .png file");
  auto options = surface_options(a.surface, cmd);
  if (!options) return fail(options.error());

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

  if (!a.rig_path.empty() && ends_with(a.input_path, ".fnet")) return fail("--rig is for an input log, not a network");
  auto network = load_input(a.input_path, a.rig_path);
  if (!network) return fail(network.error());
  SurfaceLevels surface;
  auto built = reconstruct::reconstruct_surface(*network, *options);
  if (!built) std::cerr << "fire render: no surface, drawing the curves only: " << built.error() << "\n";
  else if (!assign_quads(*built, 1, surface)) return fail("internal error: the reconstructed surface is not all quads");
  surface.level = options->levels;

  render::Box box;
  for (EdgeIndex e{0}; e < network->edge_slots(); ++e)
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
  if (drawn && a.every) {
    const int code = render_sequence(a, *options, *network, **renderer, render::frame_box(box, *view, width, height));
    const size_t messages = (*context)->validation_message_count();
    renderer->reset();
    context->reset();
    if (code == 0 && messages) return fail(std::to_string(messages) + " Vulkan validation message(s), see above");
    return code;
  }
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
      "replayed headless first. The network is reconstructed as `fire reconstruct` does with the same options and drawn with Vulkan, offscreen: "
      "the lit surface, the curves over it, the vertices as markers, the reference mesh see-through. Without a "
      "GPU, Vulkan runs on lavapipe (Debian package mesa-vulkan-drivers). FIRE_VK_VALIDATION=1 turns the "
      "validation layer on; any message then fails the command. Prints one JSON line: output, width, height, "
      "view, device, edges, surface_quads, bytes_uploaded, validation. With --every, a picture sequence of the "
      "replay instead (see --every).");
  cmd->add_option("NET", a->input_path, "curve network (.fnet) or input log")->required();
  cmd->add_option("-o,--output", a->out_path, "PNG file to write");
  cmd->add_option("--every", a->every,
                  "N: replay the input log with the renderer as the last system and write a picture to --png-dir "
                  "whenever the network changed and N frames passed since the last; one JSON line per picture "
                  "(frame, png, edges, surface_quads, bytes_uploaded, edges_uploaded, surface_vertices_uploaded)");
  cmd->add_option("--png-dir", a->png_dir, "directory for --every's frame_NNNNNN.png pictures");
  cmd->add_option("--size", a->size, "WIDTHxHEIGHT in pixels")->capture_default_str();
  cmd->add_option("--view", a->view, "iso, front, top, side or bottom (Z up)")->capture_default_str();
  cmd->add_option("--reference", a->reference_path, "OBJ mesh drawn see-through over the scene");
  add_surface_options(*cmd, a->surface);
  cmd->add_option("--rig", a->rig_path,
                  "rig file from fire calibrate, for an input log of Wii Remote reports (fire simulate drawing, a "
                  "session's input.log): its reports go through the triangulation system as in fire replay --rig");
  cmd->callback([a, cmd, &registry] { registry.exit_code = run_render(*a, *cmd); });
}

}  // namespace fire::cli
