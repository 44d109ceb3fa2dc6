#include "platform/wiimote/setup_advice.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <system_error>

#include "platform/files.hpp"
#include "platform/wiimote/device.hpp"
#include "platform/wiimote/protocol.hpp"

namespace fire::wiimote {
namespace {

namespace fs = std::filesystem;

// Where the guide takes each step; wiimote.md has the reasons.
constexpr const char* kKernelSection = " (docs/hardware.md section 6; details: docs/wiimote.md section 2)";
constexpr const char* kUdevSection = " (docs/hardware.md section 6; details: docs/wiimote.md section 3)";

// hid-core's parameter is an int (0600): "1" is what a write must say, and only root may read it.
constexpr const char* kSpecialDriversParameter = "/sys/module/hid/parameters/ignore_special_drivers";

std::string driver_title(const std::string& driver) {
  return driver == kKernelWiimoteDriver ? "hid-wiimote" : driver;
}

std::string driver_command(const std::string& hid_id, const std::string& driver, const char* action) {
  return "echo -n " + hid_id + " | sudo tee /sys/bus/hid/drivers/" + driver + "/" + action;
}

// Hands the device to hid-generic, in the order of docs/wiimote.md: the parameter first, since
// hid-generic refuses a Wii Remote while special drivers are honoured, then the rebind.
std::string to_generic_steps(const std::string& hid_id, const std::string& driver, const std::string& address,
                             std::optional<bool> ignore_special_drivers) {
  const std::string again = address.empty() ? "switch the remote off and on"
                                            : "bluetoothctl disconnect " + address + ", then press a button on the remote";
  const std::string take = (driver.empty() ? "" : driver_command(hid_id, driver, "unbind") + "; ") +
                           driver_command(hid_id, kKernelGenericDriver, "bind") + " (or reconnect it: " + again + ")";
  if (ignore_special_drivers == true) return take;
  const std::string set = ignore_special_drivers == false
                              ? "1. set hid.ignore_special_drivers: "
                              : std::string("1. unless sudo cat ") + kSpecialDriversParameter + " says 1, set it: ";
  return set + "echo 1 | sudo tee " + kSpecialDriversParameter +
         " (until reboot; for good, hid.ignore_special_drivers=1 on the kernel command line; every other HID device "
         "with a special driver then gets hid-generic too); 2. " + take;
}

std::optional<bool> read_flag(const std::string& path) {
  const Result<std::string> text = read_text_file(path);
  if (!text) return std::nullopt;
  const std::string v = text->substr(0, text->find_first_of(" \n"));
  if (v == "Y" || v == "y") return true;
  if (v == "N" || v == "n") return false;
  int n = 0;
  char rest = 0;
  if (std::sscanf(v.c_str(), "%d%c", &n, &rest) != 1) return std::nullopt;
  return n != 0;
}

struct HidIds {
  uint16_t vendor = 0, product = 0;
};

// The directory name is BUS:VENDOR:PRODUCT.N, in hex.
std::optional<HidIds> hid_ids(const std::string& hid_id) {
  unsigned bus = 0, vendor = 0, product = 0, n = 0;
  char dot = 0;
  if (std::sscanf(hid_id.c_str(), "%4x:%4x:%4x%c%x", &bus, &vendor, &product, &dot, &n) != 5 || dot != '.')
    return std::nullopt;
  return HidIds{.vendor = static_cast<uint16_t>(vendor), .product = static_cast<uint16_t>(product)};
}

std::string uevent_value(const std::string& uevent, const std::string& key) {
  std::istringstream lines(uevent);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind(key + "=", 0) == 0) return line.substr(key.size() + 1);
  return {};
}

std::string verdict_message(const SysfsRemote& r, std::optional<bool> ignore_special_drivers) {
  const std::string who = r.address.empty() ? r.hid_id : r.hid_id + " (" + r.address + ")";
  switch (r.verdict) {
    case SetupVerdict::Ready: return who + ": ready: hid-generic holds it, /dev/" + r.hidraw;
    case SetupVerdict::NotARemote: return who + ": \"" + r.name + "\" has a Wii Remote's ids but is another product: left alone";
    case SetupVerdict::KernelDriver:
      return who + ": held by the kernel's " + driver_title(r.driver) + " driver, which changes the reporting mode behind FIRE's back" +
             (ignore_special_drivers == true ? ", although hid.ignore_special_drivers is set (it was bound first): "
                                             : "; hid-generic takes a Wii Remote only while hid.ignore_special_drivers is set: ") +
             to_generic_steps(r.hid_id, r.driver, r.address, ignore_special_drivers) + kKernelSection;
    case SetupVerdict::NoNode:
      if (!r.driver.empty())
        return who + ": hid-generic holds it but made no hidraw node: sudo modprobe hidraw, then " +
               driver_command(r.hid_id, kKernelGenericDriver, "unbind") + "; " +
               driver_command(r.hid_id, kKernelGenericDriver, "bind") + kKernelSection;
      return who + ": no HID driver is bound, so there is no hidraw node for FIRE to open" +
             (ignore_special_drivers == true ? ": "
                                             : " (as after blacklisting hid_wiimote: hid-generic refuses a Wii Remote until "
                                               "hid.ignore_special_drivers is set): ") +
             to_generic_steps(r.hid_id, "", r.address, ignore_special_drivers) + kKernelSection;
  }
  return who;
}

}  // namespace

std::string udev_install_command() {
  return std::string("sudo install -m 644 ") + kUdevRule +
         " /etc/udev/rules.d/ && sudo udevadm control --reload-rules && sudo udevadm trigger";
}

bool permission_denied(const std::string& path) { return ::access(path.c_str(), R_OK | W_OK) != 0 && errno == EACCES; }

std::string permission_advice(const std::string& path) {
  return "permission denied on " + path + ": install FIRE's udev rule (" + udev_install_command() +
         "), then switch the remote off and on; from a login other than the seat's (ssh), also join its group: "
         "sudo usermod -aG plugdev $USER, and log in again" + kUdevSection;
}

std::optional<KernelBinding> kernel_binding(const std::string& hidraw_path, const std::string& sysfs_root) {
  const std::string node = fs::path(hidraw_path).filename().string();
  if (node.rfind("hidraw", 0) != 0) return std::nullopt;
  std::error_code ec;
  const fs::path device = fs::canonical(fs::path(sysfs_root) / "class" / "hidraw" / node / "device", ec);
  if (ec) return std::nullopt;
  KernelBinding b;
  b.hid_id = device.filename().string();
  const fs::path driver = fs::canonical(device / "driver", ec);
  if (!ec) b.driver = driver.filename().string();
  return b;
}

std::string unbind_advice(const KernelBinding& b) {
  return "the kernel's " + driver_title(b.driver) + " driver is bound to " + b.hid_id +
         " and changes the reporting mode behind FIRE's back; hid-generic takes a Wii Remote only while "
         "hid.ignore_special_drivers is set: " +
         to_generic_steps(b.hid_id, b.driver, "", std::nullopt) + kKernelSection;
}

SysfsSetup scan_sysfs(const std::string& sysfs_root) {
  const fs::path root(sysfs_root);
  SysfsSetup out{.devices_dir = (root / "bus" / "hid" / "devices").string(),
                 .bluetooth_dir = (root / "class" / "bluetooth").string(),
                 .adapters = {},
                 .ignore_special_drivers = read_flag((root / "module" / "hid" / "parameters" / "ignore_special_drivers").string()),
                 .remotes = {}};
  // class/bluetooth holds the adapters (hciN) and their links (hciN:HANDLE); an adapter's rfkill switch is its child.
  if (const Result<std::vector<std::string>> names = list_directory(out.bluetooth_dir); names)
    for (const std::string& name : *names) {
      if (name.rfind("hci", 0) != 0 || name.find(':') != std::string::npos) continue;
      BluetoothAdapter a{.name = name, .blocked = false};
      const fs::path dir = fs::path(out.bluetooth_dir) / name;
      if (const Result<std::vector<std::string>> children = list_directory(dir.string()); children)
        for (const std::string& child : *children)
          if (child.rfind("rfkill", 0) == 0)
            a.blocked = a.blocked || read_flag((dir / child / "soft").string()) == true ||
                        read_flag((dir / child / "hard").string()) == true;
      out.adapters.push_back(std::move(a));
    }
  const Result<std::vector<std::string>> names = list_directory(out.devices_dir);
  if (!names) return out;
  for (const std::string& hid_id : *names) {
    const std::optional<HidIds> ids = hid_ids(hid_id);
    if (!ids || !is_wii_remote(ids->vendor, ids->product)) continue;
    const fs::path dir = fs::path(out.devices_dir) / hid_id;
    const Result<std::string> uevent = read_text_file((dir / "uevent").string());
    SysfsRemote r{.hid_id = hid_id,
                  .address = uevent ? normalize_address(uevent_value(*uevent, "HID_UNIQ")) : "",
                  .name = uevent ? uevent_value(*uevent, "HID_NAME") : "",
                  .driver = {}, .hidraw = {}, .verdict = SetupVerdict::NoNode, .message = {}};
    std::error_code ec;
    const fs::path driver = fs::canonical(dir / "driver", ec);
    if (!ec) r.driver = driver.filename().string();
    if (const Result<std::vector<std::string>> nodes = list_directory((dir / "hidraw").string()); nodes)
      for (const std::string& node : *nodes)
        if (node.rfind("hidraw", 0) == 0) r.hidraw = node;
    // The Wii U Pro Controller and the Balance Board share the ids; only the name tells them apart.
    if (!is_wii_remote(ids->vendor, ids->product, r.name)) r.verdict = SetupVerdict::NotARemote;
    else if (r.driver == kKernelGenericDriver && !r.hidraw.empty()) r.verdict = SetupVerdict::Ready;
    else if (!r.driver.empty() && r.driver != kKernelGenericDriver) r.verdict = SetupVerdict::KernelDriver;
    r.message = verdict_message(r, out.ignore_special_drivers);
    out.remotes.push_back(std::move(r));
  }
  return out;
}

}  // namespace fire::wiimote
