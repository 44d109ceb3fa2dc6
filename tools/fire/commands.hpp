#pragma once
// Each area adds its subcommands to the CLI11 app; a subcommand's callback stores its exit code.
#include <CLI/CLI.hpp>
#include <string>

#include "engine/input_log.hpp"
#include "systems/triangulate/triangulate.hpp"

namespace fire::cli {

struct Registry {
  int exit_code = 0;
};

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
