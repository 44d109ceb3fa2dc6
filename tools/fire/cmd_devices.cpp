// fire devices: the Wii Remotes this machine sees, their roles, whether FIRE can use them and
// their batteries (platform/wiimote), then each set-up step it can see missed, in the guide's order.
#include <algorithm>
#include <iostream>

#include "platform/files.hpp"
#include "platform/wiimote/hidapi_backend.hpp"
#include "platform/wiimote/listing.hpp"
#include "platform/wiimote/missed_steps.hpp"
#include "platform/wiimote/setup_advice.hpp"
#include "tools/fire/commands.hpp"

namespace fire::cli {
namespace {

// The rig's "remotes"; none without --rig.
Result<std::vector<wiimote::RemoteAssignment>> rig_remotes(const std::string& path) {
  if (path.empty()) return std::vector<wiimote::RemoteAssignment>{};
  Result<std::string> text = read_text_file(path);
  if (!text) return Result<std::vector<wiimote::RemoteAssignment>>::failure(text.error());
  return wiimote::remotes_from_rig_json(*text, path);
}

// Prints the steps under a heading (nothing when none is missed); exit 1 when a remote found cannot be used.
int report_steps(const wiimote::DevicesSeen& seen) {
  const std::vector<wiimote::MissedStep> steps = wiimote::missed_steps(seen);
  if (!steps.empty()) std::cout << "steps missed, in the order of docs/hardware.md:\n";
  for (const wiimote::MissedStep& s : steps) std::cout << "  " << s.line << "\n";
  return std::any_of(steps.begin(), steps.end(), [](const wiimote::MissedStep& s) { return wiimote::cannot_use(s.step); });
}

// The --sys-root hook: sysfs alone (and the nodes under --dev-root), so a test needs neither Bluetooth nor hidapi.
// It exits as the command does: 1 only for a remote found that cannot be used, 0 with none found.
int report_sysfs(const wiimote::DevicesSeen& seen) {
  for (const wiimote::SysfsRemote& r : seen.sysfs.remotes)
    if (r.verdict == wiimote::SetupVerdict::NotARemote || r.verdict == wiimote::SetupVerdict::Ready) std::cout << r.message << "\n";
  return report_steps(seen);
}

}  // namespace

void add_devices_commands(CLI::App& app, Registry& registry) {
  struct Args {
    std::string rig_path;
    int wait_ms = 500;
    std::string sys_root;
    std::string dev_root;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "devices",
      "list the Wii Remotes found, with address, role, state and battery, then each set-up step it can see missed, one "
      "line each with what to do, in the order of docs/hardware.md: no remote connected (with --rig: each of its remotes "
      "that is not), the kernel's hid-wiimote bound instead of hid-generic (from sysfs), a hidraw node the user may not "
      "open (the udev rule), a remote that does not answer, a low battery (the remote's own flag), a remote with no role "
      "(with --rig: one it does not list; without: three or more, roles by address order). Exit 1 if a remote found "
      "cannot be used (the kernel driver, permissions, no answer), else 0, also with no remote. Not tried with real "
      "remotes: tested on fake remotes and made-up /sys trees");
  cmd->add_option("--rig", args->rig_path, "rig.json whose \"remotes\" member assigns roles by address");
  cmd->add_option("--wait-ms", args->wait_ms, "how long to wait for each remote's status report")->capture_default_str();
  CLI::Option* sys_root = cmd->add_option(
      "--sys-root", args->sys_root,
      "test hook: read this folder instead of /sys, print only what it says about the remotes and the steps missed, and "
      "open no device (exit 1 unless there is a Wii Remote there and every one is ready)");
  cmd->add_option("--dev-root", args->dev_root,
                  "test hook, with --sys-root: the folder of the hidraw nodes that tree names, instead of /dev; a node the "
                  "user may not open is named (without it, --sys-root checks no node)")
      ->needs(sys_root);
  cmd->callback([args, &registry] {
    Result<std::vector<wiimote::RemoteAssignment>> assigned = rig_remotes(args->rig_path);
    if (!assigned) {
      std::cerr << "fire devices: " << assigned.error() << "\n";
      registry.exit_code = 1;
      return;
    }
    wiimote::DevicesSeen seen{.listing = {}, .sysfs = {}, .dev_root = args->dev_root, .denied = wiimote::permission_denied,
                              .assigned = std::move(*assigned), .rig_path = args->rig_path};
    if (!args->sys_root.empty()) {
      seen.sysfs = wiimote::scan_sysfs(args->sys_root);
      registry.exit_code = report_sysfs(seen);
      return;
    }
    wiimote::HidapiBackend backend;
    Result<wiimote::Listing> listing = wiimote::list_remotes(backend, seen.assigned, args->wait_ms);
    if (!listing) {
      std::cerr << "fire devices: " << listing.error() << "\n";
      registry.exit_code = 1;
      return;
    }
    std::cout << wiimote::format_listing(*listing);
    // A remote that no driver holds has no hidraw node, so hidapi cannot see it: then only sysfs speaks.
    seen.listing = std::move(*listing);
    seen.sysfs = wiimote::scan_sysfs();
    seen.dev_root = "/dev";
    registry.exit_code = report_steps(seen);
  });
}

}  // namespace fire::cli
