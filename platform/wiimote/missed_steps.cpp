#include "platform/wiimote/missed_steps.hpp"

#include <algorithm>
#include <optional>

namespace fire::wiimote {
namespace {

constexpr const char* kConnectSection = " (docs/hardware.md section 5)";
constexpr const char* kBatterySection = " (docs/hardware.md section 1)";
constexpr const char* kRoleSection = " (docs/hardware.md section 7)";

// One Wii Remote as hidapi listed it, as sysfs shows it, or both, matched by address.
struct Seen {
  std::string address;  // normalized; empty when neither says
  std::string node;     // its hidraw node; empty: none, or not looked up
  const ListedRemote* listed = nullptr;
  const SysfsRemote* sys = nullptr;
  std::optional<Role> role;
};

bool kernel_step(const SysfsRemote* r) {
  return r && (r->verdict == SetupVerdict::KernelDriver || r->verdict == SetupVerdict::NoNode);
}

std::string who(const Seen& s) {
  const std::string name = !s.address.empty() ? s.address : s.sys ? s.sys->hid_id : s.node;
  return s.role ? std::string(role_name(*s.role)) + " " + name : name;
}

std::string rig_name(const DevicesSeen& in) { return in.rig_path.empty() ? "the rig file" : in.rig_path; }

std::vector<Seen> merge(const DevicesSeen& in) {
  std::vector<Seen> out;
  for (const ListedRemote& r : in.listing.remotes)
    out.push_back({.address = r.address, .node = r.info.path, .listed = &r, .sys = nullptr, .role = {}});
  for (const SysfsRemote& r : in.sysfs.remotes) {
    if (r.verdict == SetupVerdict::NotARemote) continue;
    auto it = std::find_if(out.begin(), out.end(),
                           [&](const Seen& s) { return !r.address.empty() && s.address == r.address; });
    if (it == out.end()) it = out.insert(out.end(), Seen{.address = r.address, .node = {}, .listed = nullptr, .sys = nullptr, .role = {}});
    it->sys = &r;
    if (it->node.empty() && !r.hidraw.empty() && !in.dev_root.empty()) it->node = in.dev_root + "/" + r.hidraw;
  }
  // The roles the driver gives, over every remote seen: what they will be once all of them can be opened.
  std::vector<DeviceInfo> found;
  for (const Seen& s : out)
    if (!s.address.empty())
      found.push_back({.vendor = kNintendoVendor, .product = kProductRemote, .serial = s.address, .path = {}, .product_name = {}});
  for (Seen& s : out)
    if (!s.address.empty()) s.role = role_of(s.address, in.assigned, found);
  std::stable_sort(out.begin(), out.end(), [](const Seen& a, const Seen& b) { return a.address < b.address; });
  return out;
}

void connect_steps(const DevicesSeen& in, const std::vector<Seen>& seen, std::vector<MissedStep>& out) {
  if (seen.empty()) {
    const auto& adapters = in.sysfs.adapters;
    const bool all_blocked =
        !adapters.empty() && std::all_of(adapters.begin(), adapters.end(), [](const BluetoothAdapter& a) { return a.blocked; });
    if (adapters.empty())
      out.push_back({Step::Connect, "no Wii Remote found, and no Bluetooth adapter (none in " + in.sysfs.bluetooth_dir +
                                        "): plug in a Bluetooth Classic adapter (docs/hardware.md section 1), then pair and "
                                        "connect the remotes" + kConnectSection});
    else if (all_blocked)
      out.push_back({Step::Connect, "no Wii Remote found: the Bluetooth adapter " + adapters.front().name +
                                        " is switched off (rfkill blocks it): rfkill unblock bluetooth, then pair and connect "
                                        "the remotes" + kConnectSection});
    else if (in.assigned.empty())
      out.push_back({Step::Connect, "no Wii Remote found: none is connected: pair and connect them; a paired and trusted "
                                    "remote reconnects when you press a button on it" + std::string(kConnectSection)});
  }
  std::vector<RemoteAssignment> listed = in.assigned;
  std::sort(listed.begin(), listed.end(), [](const auto& a, const auto& b) { return a.address < b.address; });
  for (const RemoteAssignment& a : listed)
    if (std::none_of(seen.begin(), seen.end(), [&](const Seen& s) { return s.address == a.address; }))
      out.push_back({Step::Connect, std::string(role_name(a.role)) + " " + a.address + " (" + rig_name(in) +
                                        ") is not connected: press a button on it to reconnect it, or pair and connect it "
                                        "if it was never paired on this PC" + kConnectSection});
}

void role_steps(const DevicesSeen& in, const std::vector<Seen>& seen, std::vector<MissedStep>& out) {
  if (!in.assigned.empty()) {
    const auto pad = std::find_if(in.assigned.begin(), in.assigned.end(),
                                  [](const RemoteAssignment& a) { return a.role == Role::CommandPad; });
    for (const Seen& s : seen) {
      if (s.address.empty() || s.role) continue;
      const std::string head = s.address + ": not in the \"remotes\" of " + rig_name(in) + ", so fire app --live leaves it alone";
      if (pad == in.assigned.end())
        out.push_back({Step::Role, head + ": if it is the pad (switched off while calibrating), add {\"address\": \"" +
                                       s.address + "\", \"role\": \"pad\"} to that list" + kRoleSection});
      else
        out.push_back({Step::Role, head + ": the pad there is " + pad->address +
                                       "; switch this one off, or put its address in place of the remote it replaces" +
                                       kRoleSection});
    }
    return;
  }
  std::string roles;
  size_t remotes = 0;
  for (const Seen& s : seen) {
    if (s.address.empty()) continue;
    roles += std::string(remotes++ ? ", " : "") + s.address + " " + (s.role ? std::string(role_name(*s.role)) : "none (left alone)");
  }
  // Two remotes are the cameras whatever their order; from the third on, the order of the addresses decides.
  if (remotes < 3) return;
  const std::string rig = in.rig_path.empty() ? "no rig file" : in.rig_path + " without \"remotes\"";
  out.push_back({Step::Role, std::to_string(remotes) + " Wii Remotes and " + rig + ", so the roles go by address order: " +
                                 roles +
                                 ": switch the pad off while you aim and calibrate (a pad whose address sorts first would "
                                 "be taken as a camera), then add it to the rig's \"remotes\"" + kRoleSection});
}

}  // namespace

std::vector<MissedStep> missed_steps(const DevicesSeen& in) {
  const std::vector<Seen> seen = merge(in);
  std::vector<MissedStep> out;
  connect_steps(in, seen, out);
  const auto denied = [&](const Seen& s) { return !s.node.empty() && in.denied && in.denied(s.node); };
  for (const Seen& s : seen) {
    if (kernel_step(s.sys)) out.push_back({Step::KernelDriver, s.sys->message});
    if (denied(s)) out.push_back({Step::Permissions, who(s) + ": " + permission_advice(s.node)});
    // What hidapi could not open or hear for a reason the steps above do not name.
    if (s.listed && s.listed->state != ListedState::Ready && !kernel_step(s.sys) && !denied(s))
      out.push_back({Step::Answer, who(s) + ": " + s.listed->problem});
    if (s.listed && s.listed->status && s.listed->status->battery_low())
      out.push_back({Step::Battery, who(s) + ": its battery is low (" + std::to_string(battery_percent(*s.listed->status)) +
                                        " %): put in fresh AA cells before the session, never during one" + kBatterySection});
  }
  role_steps(in, seen, out);
  std::stable_sort(out.begin(), out.end(), [](const MissedStep& a, const MissedStep& b) { return a.step < b.step; });
  return out;
}

}  // namespace fire::wiimote
