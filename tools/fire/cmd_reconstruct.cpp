// fire reconstruct: a curve network to a smooth surface file (thesis chapter 6, or the FIRE pipeline).
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "platform/clock.hpp"
#include "platform/network_file.hpp"
#include "platform/surface_io.hpp"
#include "systems/reconstruct/reconstruct.hpp"
#include "tools/fire/commands.hpp"

namespace fire::cli {

namespace {

struct ReconstructArgs {
  std::string network_path, out_path, method = "fire", planarity = "least-squares";
  uint32_t coons_steps = 1, levels = 3;
  double fairness = reconstruct::Options{}.fairness;
  bool fairness_given = false;
};

int fail(const std::string& message) {
  std::cerr << "fire reconstruct: " << message << "\n";
  return 1;
}

int run_reconstruct(const ReconstructArgs& a) {
  reconstruct::Options options;
  if (a.method == "fire") options.method = reconstruct::Method::fire;
  else if (a.method == "thesis") options.method = reconstruct::Method::thesis;
  else return fail("--method must be thesis or fire, not '" + a.method + "'");
  if (a.planarity == "least-squares") options.planarity = reconstruct::Planarity::least_squares;
  else if (a.planarity == "mean-normal") options.planarity = reconstruct::Planarity::mean_normal;
  else if (a.planarity == "hough") options.planarity = reconstruct::Planarity::hough;
  else return fail("--planarity must be least-squares, mean-normal or hough, not '" + a.planarity + "'");
  options.coons_steps = a.coons_steps;
  options.levels = a.levels;
  options.fairness = a.fairness;
  options.fairness_from_noise = !a.fairness_given;
  // The output's format is checked first, so a wrong extension costs no reconstruction.
  if (auto format = surface_format_of(a.out_path); !format) return fail(format.error());
  auto net = load_network(a.network_path);
  if (!net) return fail(net.error());

  reconstruct::ReconstructionState state;
  SurfaceMesh surface;
  const int64_t start = monotonic_ns();
  const Status built = reconstruct::reconstruct_update(*net, options, state, surface);
  const double seconds = double(monotonic_ns() - start) * 1e-9;
  if (!built) return fail(a.network_path + ": " + built.error);
  if (auto written = write_surface(surface, a.out_path); !written) return fail(written.error);

  nlohmann::ordered_json out;
  out["method"] = a.method;
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
      "positions with limit normals, atomically; the format follows the extension (.obj .ply .stl .glb). Prints one "
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
  cmd->add_option("-o,--output", a->out_path, "surface file to write: .obj, .ply, .stl or .glb")->required();
  cmd->add_option("--method", a->method, "thesis or fire")->capture_default_str();
  cmd->add_option("--coons-steps", a->coons_steps, "N: Coons refinement steps (1 to 5)")->capture_default_str();
  cmd->add_option("--levels", a->levels, "L: Catmull-Clark levels (1 to 6)")->capture_default_str();
  cmd->add_option("--fairness", a->fairness,
                  "fire: weight of the fit's smoothness term, 0 to 1 (smaller follows the curves more closely, larger "
                  "keeps face interiors smoother). Default: this for exact curves, raised with the noise the "
                  "polylines show (0.1 for a noise estimate of 3e-3 to 1.3e-2, beyond with its square, up to 1); given, it "
                  "is used as is")
      ->capture_default_str();
  cmd->add_option("--planarity", a->planarity,
                  "the thesis triquadrification's measure: least-squares, mean-normal or hough")
      ->capture_default_str();
  cmd->callback([a, cmd, &registry] {
    a->fairness_given = cmd->count("--fairness") > 0;
    registry.exit_code = run_reconstruct(*a);
  });
}

}  // namespace fire::cli
