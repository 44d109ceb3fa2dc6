// fire: the command-line entry point. Each area registers its subcommands here.
#include <CLI/CLI.hpp>

#include <iostream>
#include <string>

#include "fire_version.hpp"
#include "tools/fire/commands.hpp"

namespace {

// A usage error (an unknown command or option, a missing or malformed argument) exits 2, as command-line tools
// do, naming the command it is about; CLI11's own exit codes (104 to 109) say nothing to a script.
constexpr int kUsageError = 2;

std::string command_path(const CLI::App& app) {
  std::string path = "fire";
  for (const CLI::App* sub = &app; !sub->get_subcommands().empty();) {
    sub = sub->get_subcommands().front();
    path += ' ' + sub->get_name();
  }
  return path;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"FIRE: Fast Interactive Reverse Engineering. Curves drawn on an object become a smooth 3D surface."};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("fire ") + FIRE_VERSION + " (commit " + FIRE_COMMIT + ")");
  fire::cli::Registry registry;
  fire::cli::add_network_commands(app, registry);
  fire::cli::add_synth_commands(app, registry);
  fire::cli::add_tracking_commands(app, registry);
  fire::cli::add_eval_commands(app, registry);
  fire::cli::add_reconstruct_commands(app, registry);
  fire::cli::add_devices_commands(app, registry);
  fire::cli::add_aim_commands(app, registry);
  fire::cli::add_render_commands(app, registry);
  fire::cli::add_app_commands(app, registry);
  // A first word that names no command: say so, not that a command is required.
  if (argc > 1 && argv[1][0] != '-') {
    const std::string word = argv[1];
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands({})) known = known || sub->check_name(word);
    if (!known) {
      std::cerr << "fire: '" << word << "' is not a command (fire --help lists them)\n";
      return kUsageError;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << command_path(app) << ": " << e.what() << " (" << command_path(app) << " --help)\n";
    return kUsageError;
  }
  return registry.exit_code;
}
