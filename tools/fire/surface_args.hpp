#pragma once
// The surface options of the commands that reconstruct a network once (reconstruct, render), written once so
// that a picture can show exactly the surface an export holds.
#include <CLI/CLI.hpp>
#include <string>

#include "engine/common.hpp"
#include "platform/surface_io.hpp"
#include "systems/reconstruct/reconstruct.hpp"

namespace fire::cli {

struct SurfaceArgs {
  std::string method = "fire", planarity = "least-squares";
  uint32_t coons_steps = reconstruct::Options{}.coons_steps;
  uint32_t levels = reconstruct::Options{}.levels;
  double fairness = reconstruct::Options{}.fairness;
};

// --method, --coons-steps, --levels, --fairness and --planarity on `cmd`.
void add_surface_options(CLI::App& cmd, SurfaceArgs& args);
// Whether any of them is on `cmd`'s command line (a session folder's settings.json decides them instead).
bool surface_options_given(const CLI::App& cmd);
// The options they give (an explicit --fairness is used as is), or what is wrong with them. Call after
// parsing: it asks `cmd` whether --fairness was given.
Result<reconstruct::Options> surface_options(const SurfaceArgs& args, const CLI::App& cmd);

// --units on `cmd`: the length unit of the mesh (and CAD) files it writes.
void add_units_option(CLI::App& cmd, std::string& units);
// The unit --units names (millimetres when not given); an error when it names none of ours, or when given
// with a .glb among `paths` (glTF is metres by its specification).
Result<LengthUnit> export_unit(const std::string& units, const CLI::App& cmd, const std::vector<std::string>& paths);

}  // namespace fire::cli
