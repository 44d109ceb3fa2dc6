// fire: the command-line entry point. Each area registers its subcommands here.
#include <CLI/CLI.hpp>

#include "tools/fire/commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"FIRE: Fast Interactive Reverse Engineering. Curves drawn on an object become a smooth 3D surface."};
  app.require_subcommand(1);
  fire::cli::Registry registry;
  fire::cli::add_network_commands(app, registry);
  fire::cli::add_synth_commands(app, registry);
  fire::cli::add_tracking_commands(app, registry);
  fire::cli::add_eval_commands(app, registry);
  fire::cli::add_reconstruct_commands(app, registry);
  fire::cli::add_devices_commands(app, registry);
  fire::cli::add_render_commands(app, registry);
  fire::cli::add_app_commands(app, registry);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  return registry.exit_code;
}
