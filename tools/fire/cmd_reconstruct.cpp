// fire reconstruct: a curve network to a smooth surface file (thesis chapter 6, or the FIRE pipeline).
#include <iostream>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>

#include "platform/clock.hpp"
#include "platform/cad/cad_export.hpp"
#include "platform/cage_io.hpp"
#include "platform/network_file.hpp"
#include "platform/surface_io.hpp"
#include "systems/reconstruct/reconstruct.hpp"
#include "systems/catmull_clark/bspline_patches.hpp"
#include "tools/fire/commands.hpp"
#include "tools/fire/surface_args.hpp"

namespace fire::cli {

namespace {

struct ReconstructArgs {
  std::string network_path, out_path;
  std::vector<std::string> cage_paths;
  std::string units = unit_name(kDefaultExportUnit);
  SurfaceArgs surface;
};

int fail(const std::string& message) {
  std::cerr << "fire reconstruct: " << message << "\n";
  return 1;
}

int run_reconstruct(const ReconstructArgs& a, const CLI::App& cmd) {
  auto parsed = surface_options(a.surface, cmd);
  if (!parsed) return fail(parsed.error());
  const reconstruct::Options& options = *parsed;
  if (a.out_path.empty() && a.cage_paths.empty()) {
    std::cerr << "fire reconstruct: nothing to write: give -o SURFACE, --cage CAGE or both\n";
    return 2;
  }
  // The outputs' formats are checked first, so a wrong extension costs no reconstruction.
  const bool to_cad = !a.out_path.empty() && cad::cad_format_of(a.out_path).ok();
  if (to_cad && !cad::cad_available())
    return fail(a.out_path + ": this fire was built without OpenCASCADE, so it writes no STEP or IGES (install "
                "libocct-data-exchange-dev and build again, or write a mesh: .obj, .ply, .stl, .glb)");
  if (!a.out_path.empty() && !to_cad)
    if (auto format = surface_format_of(a.out_path); !format)
      return fail(format.error() + "; or .step, .stp, .igs, .iges for CAD");
  for (const std::string& path : a.cage_paths)
    if (Status s = check_cage_path(path); !s) return fail(s.error);
  auto unit = export_unit(a.units, cmd, {a.out_path});
  if (!unit) return fail(unit.error());
  auto net = load_network(a.network_path);
  if (!net) return fail(net.error());

  reconstruct::ReconstructionState state;
  SurfaceMesh surface;
  const int64_t start = monotonic_ns();
  const Status built = reconstruct::reconstruct_update(*net, options, state, surface);
  const double seconds = double(monotonic_ns() - start) * 1e-9;
  if (!built) return fail(a.network_path + ": " + built.error);
  // The cage, once, for the CAD export and the cage files.
  std::optional<Cage> cage;
  if (to_cad || !a.cage_paths.empty()) cage = reconstruct::cage_of(state, options, surface);
  nlohmann::ordered_json cad_out;
  if (to_cad) {
    auto converted = catmull_clark::bspline_patches(*cage);
    if (!converted) return fail(a.network_path + ": " + converted.error());
    auto written = cad::write_cad(converted->patches, a.out_path, *unit);
    if (!written) return fail(written.error());
    cad_out["patches"] = converted->patches.patch_count();
    cad_out["exact"] = converted->exact;
    cad_out["fitted"] = converted->fitted;
    cad_out["max_fit_error"] = converted->max_fit_error;
    cad_out["solids"] = written->solids;
    cad_out["shells"] = written->shells;
    cad_out["free_edges"] = written->free_edges;
    cad_out["units"] = unit_name(*unit);
  } else if (!a.out_path.empty()) {
    if (auto written = write_surface(surface, a.out_path, *unit); !written) return fail(written.error);
  }
  for (const std::string& path : a.cage_paths)
    if (Status written = write_cage(*cage, path, *unit); !written) return fail(written.error);

  nlohmann::ordered_json out;
  out["method"] = a.surface.method;
  out["coons_steps"] = options.coons_steps;
  out["levels"] = options.levels;
  out["base_faces"] = state.base().face_count();
  out["faces"] = surface.face_count();
  out["vertices"] = surface.positions.size();
  out["seconds"] = seconds;
  out["worst_quad_aspect"] = reconstruct::worst_quad_aspect(state.base());
  const double noise = reconstruct::noise_estimate(*net), spread = reconstruct::tangent_spread_deg(*net);
  out["noise_estimate"] = noise;
  out["tangent_spread_deg"] = spread;
  out["fairness"] = reconstruct::fit_fairness(options, reconstruct::fit_noise(noise, spread));
  out["short_curves"] = state.short_curves();
  out["joined_vertices"] = state.joined_vertices();
  if (to_cad) out["cad"] = cad_out;
  std::cout << out.dump() << "\n";
  return 0;
}

}  // namespace

void add_reconstruct_commands(CLI::App& app, Registry& registry) {
  auto a = std::make_shared<ReconstructArgs>();
  CLI::App* cmd = app.add_subcommand("reconstruct", "Reconstruct a smooth surface from a curve network");
  cmd->footer(
      "thesis: triquadrification, Coons refinement and Catmull-Clark (thesis chapter 6). fire (default): n quads "
      "around a centre per face from an n-sided transfinite patch, then base points fitted so that the "
      "Catmull-Clark limit surface passes through the drawn curves. Writes the level-L quads at their limit "
      "positions with limit normals, atomically; the format follows the extension (.obj .ply .stl .glb), in --units, +Z up (.glb: metres, +Y up). Prints one "
      "JSON line: method, coons_steps, levels, base_faces, faces, vertices, seconds (reconstruction only, no I/O) "
      "worst_quad_aspect (the base mesh's worst quad: longest side squared over area, 1 for a square), "
      "noise_estimate (the polylines' noise from their samples' third differences, a fraction of their mean "
      "length), tangent_spread_deg (the median angle by which the curves leaving a vertex lie out of one plane: "
      "over 2, curves with a noise estimate under 3e-4 count as noisy as 3e-3) and fairness (the fit's weight: "
      "--fairness if given, else the default for exact curves raised with the noise estimate: 0.1 from 3e-3 to "
      "1.3e-2, beyond with its square, up to 1), short_curves (without --fairness, noisy curves that reach "
      "less than 6 noise deviations from their ends, which the surface takes nearer their chords, as a chord "
      "below 3: how many there were) and joined_vertices (without --fairness, for noisy curves: inner network "
      "vertices where just two curves meet, which the surface runs through as through any curve sample "
      "instead of making them vertices of its base mesh).");
  cmd->add_option("NET", a->network_path, "curve network file (format: engine/NETWORK_FORMAT.md)")->required();
  cmd->add_option("-o,--output", a->out_path,
                  "surface file to write: a mesh (.obj, .ply, .stl or .glb), or CAD (.step or .stp: STEP AP214; .igs or "
                  ".iges: IGES): one bicubic B-spline patch per face of the limit surface, exact where the face is "
                  "regular, fitted within 1e-4 of the diagonal around extraordinary vertices, sewn into one shell (a "
                  "closed object a solid), in --units");
  cmd->add_option("--cage", a->cage_paths,
                  "also (or instead) write the subdivision cage whose Catmull-Clark limit the surface is: the base mesh "
                  "at its fitted points, for subdivision modellers; .obj with OpenSubdiv's tags (t interpolateboundary, "
                  "t crease, t corner) or .usda (a USD Mesh prim with subdivisionScheme, interpolateBoundary, creases "
                  "and corners; sharpness 10 is infinitely sharp); in --units; repeat it for both")
      ->allow_extra_args(false);
  add_units_option(*cmd, a->units);
  add_surface_options(*cmd, a->surface);
  cmd->callback([a, cmd, &registry] { registry.exit_code = run_reconstruct(*a, *cmd); });
}

}  // namespace fire::cli
