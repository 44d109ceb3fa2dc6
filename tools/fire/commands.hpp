#pragma once
// Each area adds its subcommands to the CLI11 app; a subcommand's callback stores its exit code.
#include <CLI/CLI.hpp>
#include <sstream>
#include <string>

#include "engine/input_log.hpp"
#include "systems/triangulate/triangulate.hpp"

namespace fire::cli {

struct Registry {
  int exit_code = 0;
};

// A number option's lower bound. CLI11's PositiveNumber and NonNegativeNumber write the whole double range out
// in their message (0.000000 to a 309-digit number); this says what the value must be.
inline CLI::Validator at_least(double least, const std::string& description) {
  return CLI::Validator(
      [least](std::string& text) -> std::string {
        double value = 0;
        if (!CLI::detail::lexical_cast(text, value)) return "'" + text + "' is not a number";
        if (value >= least) return {};
        std::ostringstream message;
        message << "must be at least " << least << ", not " << text;
        return message.str();
      },
      description);
}
inline const CLI::Validator kPositive = at_least(1, "POSITIVE");  // counts: 1 or more
inline const CLI::Validator kNonNegative = at_least(0, "NONNEGATIVE");

// replay, open, export-network (engine foundation)
void add_network_commands(CLI::App& app, Registry& registry);
// network-from-mesh (synthetic curve networks, systems/synth)
void add_synth_commands(CLI::App& app, Registry& registry);

// simulate wand|sketch, calibrate, track (stereo tracking, systems/tracking)
void add_tracking_commands(CLI::App& app, Registry& registry);

// eval (surface distance to a reference limit surface, systems/evaluate)
void add_eval_commands(CLI::App& app, Registry& registry);

// reconstruct (curve network to smooth surface, systems/reconstruct)
void add_reconstruct_commands(CLI::App& app, Registry& registry);

// devices (the Wii Remotes this machine sees, platform/wiimote)
void add_devices_commands(CLI::App& app, Registry& registry);
// aim (each camera remote's IR view while the cameras are aimed, tools/app/aim_run.hpp)
void add_aim_commands(CLI::App& app, Registry& registry);
// render (headless Vulkan rendering to PNG, platform/render)
void add_render_commands(CLI::App& app, Registry& registry);
// app (the interactive window and HUD, platform/window)
void add_app_commands(CLI::App& app, Registry& registry);

}  // namespace fire::cli
