#include "tools/fire/surface_args.hpp"

namespace fire::cli {

void add_surface_options(CLI::App& cmd, SurfaceArgs& a) {
  cmd.add_option("--method", a.method, "thesis or fire")->capture_default_str();
  cmd.add_option("--coons-steps", a.coons_steps,
                 "N: Coons refinement steps (1 to " + std::to_string(reconstruct::kMaxCoonsSteps) + ")")
      ->capture_default_str();
  cmd.add_option("--levels", a.levels,
                 "L: Catmull-Clark levels (1 to " + std::to_string(reconstruct::kMaxSurfaceLevels) + ")")
      ->capture_default_str();
  cmd.add_option("--fairness", a.fairness,
                 "fire: weight of the fit's smoothness term, 0 to 1 (smaller follows the curves more closely, larger "
                 "keeps face interiors smoother). Default: this for exact curves, raised with the noise the "
                 "polylines show (0.1 for a noise estimate of 3e-3 to 1.3e-2, beyond with its square, up to 1); given, it "
                 "is used as is and the curves are fitted as exact ones (no noise estimate: no thin-quad shape "
                 "term, and the polylines are read on the smooth curve through their samples)")
      ->capture_default_str();
  cmd.add_option("--planarity", a.planarity, "the thesis triquadrification's measure: least-squares, mean-normal or hough")
      ->capture_default_str();
}

bool surface_options_given(const CLI::App& cmd) {
  for (const char* option : {"--method", "--coons-steps", "--levels", "--fairness", "--planarity"})
    if (cmd.count(option) > 0) return true;
  return false;
}

Result<reconstruct::Options> surface_options(const SurfaceArgs& a, const CLI::App& cmd) {
  using R = Result<reconstruct::Options>;
  reconstruct::Options options;
  if (a.method == "fire") options.method = reconstruct::Method::Fire;
  else if (a.method == "thesis") options.method = reconstruct::Method::Thesis;
  else return R::failure("--method must be thesis or fire, not '" + a.method + "'");
  if (a.planarity == "least-squares") options.planarity = reconstruct::Planarity::LeastSquares;
  else if (a.planarity == "mean-normal") options.planarity = reconstruct::Planarity::MeanNormal;
  else if (a.planarity == "hough") options.planarity = reconstruct::Planarity::Hough;
  else return R::failure("--planarity must be least-squares, mean-normal or hough, not '" + a.planarity + "'");
  options.coons_steps = a.coons_steps;
  options.levels = a.levels;
  options.fairness = a.fairness;
  options.fairness_from_noise = cmd.count("--fairness") == 0;
  if (Status s = reconstruct::check_options(options); !s) return R::failure(s.error);
  return options;
}

void add_units_option(CLI::App& cmd, std::string& units) {
  cmd.add_option("--units", units,
                 "length unit of the .obj, .ply and .stl written: mm, cm or m (FIRE works in metres; the file says "
                 "which unit it holds, and +Z up). A .glb is always in metres and +Y up, as glTF requires")
      ->capture_default_str();
}

Result<LengthUnit> export_unit(const std::string& units, const CLI::App& cmd, const std::vector<std::string>& paths) {
  auto unit = length_unit_of(units);
  if (!unit) return Result<LengthUnit>::failure("--units: " + unit.error());
  if (cmd.count("--units") > 0 && *unit != LengthUnit::Metre)
    for (const std::string& path : paths)
      if (auto format = surface_format_of(path); format && *format == SurfaceFormat::Glb)
        return Result<LengthUnit>::failure("--units " + units + " cannot apply to " + path +
                                           ": a glTF file is in metres by its specification");
  return unit;
}

}  // namespace fire::cli
