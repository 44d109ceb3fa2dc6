// fire devices: the Wii Remotes this machine sees, their roles, whether FIRE can use them and
// their batteries (platform/wiimote).
#include <iostream>

#include "platform/files.hpp"
#include "platform/wiimote/hidapi_backend.hpp"
#include "platform/wiimote/listing.hpp"
#include "tools/fire/commands.hpp"

namespace fire::cli {

void add_devices_commands(CLI::App& app, Registry& registry) {
  struct Args {
    std::string rig_path;
    int wait_ms = 500;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "devices", "list the Wii Remotes found, with address, role, state and battery (exit 1 if one cannot be used)");
  cmd->add_option("--rig", args->rig_path, "rig.json whose \"remotes\" member assigns roles by address");
  cmd->add_option("--wait-ms", args->wait_ms, "how long to wait for each remote's status report")->capture_default_str();
  cmd->callback([args, &registry] {
    std::vector<wiimote::RemoteAssignment> assigned;
    if (!args->rig_path.empty()) {
      Result<std::string> text = read_text_file(args->rig_path);
      if (!text) {
        std::cerr << "fire devices: " << text.error() << "\n";
        registry.exit_code = 1;
        return;
      }
      Result<std::vector<wiimote::RemoteAssignment>> roles = wiimote::remotes_from_rig_json(*text, args->rig_path);
      if (!roles) {
        std::cerr << "fire devices: " << roles.error() << "\n";
        registry.exit_code = 1;
        return;
      }
      assigned = std::move(*roles);
    }
    wiimote::HidapiBackend backend;
    Result<wiimote::Listing> listing = wiimote::list_remotes(backend, assigned, args->wait_ms);
    if (!listing) {
      std::cerr << "fire devices: " << listing.error() << "\n";
      registry.exit_code = 1;
      return;
    }
    std::cout << wiimote::format_listing(*listing);
    for (const wiimote::ListedRemote& r : listing->remotes)
      if (r.state != wiimote::ListedState::Ready) registry.exit_code = 1;
  });
}

}  // namespace fire::cli
