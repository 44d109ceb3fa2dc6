// fire devices: the Wii Remotes this machine sees, their roles, whether FIRE can use them and
// their batteries (platform/wiimote), and what sysfs says still stands between a remote and FIRE.
#include <algorithm>
#include <iostream>

#include "platform/files.hpp"
#include "platform/wiimote/hidapi_backend.hpp"
#include "platform/wiimote/listing.hpp"
#include "platform/wiimote/setup_advice.hpp"
#include "tools/fire/commands.hpp"

namespace fire::cli {
namespace {

bool is_remote(const wiimote::SysfsRemote& r) { return r.verdict != wiimote::SetupVerdict::NotARemote; }
bool not_ready(const wiimote::SysfsRemote& r) { return is_remote(r) && r.verdict != wiimote::SetupVerdict::Ready; }

// The --sys-root hook: sysfs alone, so a test needs neither Bluetooth nor hidapi.
int report_sysfs(const std::string& root) {
  const wiimote::SysfsSetup setup = wiimote::scan_sysfs(root);
  int remotes = 0, stuck = 0;
  for (const wiimote::SysfsRemote& r : setup.remotes) {
    std::cout << r.message << "\n";
    remotes += is_remote(r);
    stuck += not_ready(r);
  }
  if (remotes == 0) {
    std::cout << "no Wii Remote found under " << setup.devices_dir << " (pair and connect one first: docs/wiimote.md)\n";
    return 1;
  }
  return stuck ? 1 : 0;
}

}  // namespace

void add_devices_commands(CLI::App& app, Registry& registry) {
  struct Args {
    std::string rig_path;
    int wait_ms = 500;
    std::string sys_root;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "devices",
      "list the Wii Remotes found, with address, role, state and battery, then each remote that sysfs shows the kernel "
      "has not handed to hid-generic, with the missing step (exit 1 if one cannot be used)");
  cmd->add_option("--rig", args->rig_path, "rig.json whose \"remotes\" member assigns roles by address");
  cmd->add_option("--wait-ms", args->wait_ms, "how long to wait for each remote's status report")->capture_default_str();
  cmd->add_option("--sys-root", args->sys_root,
                  "test hook: read this folder instead of /sys, print only what it says about the remotes and open "
                  "no device (exit 1 unless every Wii Remote there is ready)");
  cmd->callback([args, &registry] {
    if (!args->sys_root.empty()) {
      registry.exit_code = report_sysfs(args->sys_root);
      return;
    }
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
    // A remote that no driver holds has no hidraw node, so hidapi cannot see it: then only sysfs speaks.
    const wiimote::SysfsSetup setup = wiimote::scan_sysfs();
    const bool any_stuck = std::any_of(setup.remotes.begin(), setup.remotes.end(), not_ready);
    if (!listing->remotes.empty() || !any_stuck) std::cout << wiimote::format_listing(*listing);
    for (const wiimote::ListedRemote& r : listing->remotes)
      if (r.state != wiimote::ListedState::Ready) registry.exit_code = 1;
    for (const wiimote::SysfsRemote& r : setup.remotes)
      if (not_ready(r)) std::cout << r.message << "\n";
    if (any_stuck) registry.exit_code = 1;
  });
}

}  // namespace fire::cli
