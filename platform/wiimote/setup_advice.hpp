#pragma once
// What stands between a paired remote and FIRE on Linux, found from sysfs, and the commands that
// fix it (docs/wiimote.md explains them). Kept apart from the hidapi backend so tests can run it
// on a made-up sysfs tree.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace fire::wiimote {

// The udev rule FIRE ships, and the command that installs it, from the source tree's root.
inline constexpr const char* kUdevRule = "platform/wiimote/99-fire-wiimote.rules";
std::string udev_install_command();
// Whether the user may not open `path` for reading and writing (EACCES; root always may).
bool permission_denied(const std::string& path);
// For a device the user may not open: the udev rule, and the group for a login other than the seat's.
std::string permission_advice(const std::string& path);

struct KernelBinding {
  std::string hid_id;  // the HID device behind the hidraw node, e.g. 0005:057E:0306.0003
  std::string driver;  // the kernel driver bound to it; "wiimote" is hid-wiimote
};
inline constexpr const char* kKernelWiimoteDriver = "wiimote";
inline constexpr const char* kKernelGenericDriver = "hid-generic";

// The HID device behind a hidraw node (/dev/hidrawN) and its bound driver, read from
// <sysfs_root>/class/hidraw/hidrawN/device; nullopt when sysfs does not say.
std::optional<KernelBinding> kernel_binding(const std::string& hidraw_path, const std::string& sysfs_root = "/sys");
// How to hand the remote from hid-wiimote, which sends its own reporting modes beside FIRE, to
// hid-generic: hid.ignore_special_drivers first, then the rebind.
std::string unbind_advice(const KernelBinding& binding);

// Where a device with a Wii Remote's ids stands with the kernel (docs/wiimote.md, section 2).
enum class SetupVerdict : uint8_t {
  Ready,         // hid-generic holds it and made a hidraw node
  KernelDriver,  // another driver holds it: hid-wiimote, as a rule
  NoNode,        // no driver bound (or one that made no hidraw node): nothing for FIRE to open
  NotARemote,    // same ids, another product (Wii U Pro Controller, Balance Board): left alone
};

struct SysfsRemote {
  std::string hid_id;   // 0005:057E:0306.0003
  std::string address;  // HID_UNIQ, normalized; empty when the uevent has none
  std::string name;     // HID_NAME
  std::string driver;   // the bound driver's name; empty: none
  std::string hidraw;   // hidrawK; empty: none
  SetupVerdict verdict = SetupVerdict::NoNode;
  std::string message;  // names the device and, unless it is ready or not a remote, the missing step and its commands
};

struct BluetoothAdapter {
  std::string name;      // hci0
  bool blocked = false;  // rfkill blocks it (soft or hard): switched off
};

struct SysfsSetup {
  std::string devices_dir;                      // <root>/bus/hid/devices, for messages
  std::string bluetooth_dir;                    // <root>/class/bluetooth, for messages
  std::vector<BluetoothAdapter> adapters;       // by name; none: no adapter, or the bluetooth module is not loaded
  std::optional<bool> ignore_special_drivers;   // nullopt: absent or unreadable (only root may read it)
  std::vector<SysfsRemote> remotes;             // every device with a Wii Remote's ids, by hid id
};

// Reads <sysfs_root>/bus/hid/devices, <sysfs_root>/module/hid/parameters/ignore_special_drivers and the
// adapters in <sysfs_root>/class/bluetooth with their rfkill switches.
SysfsSetup scan_sysfs(const std::string& sysfs_root = "/sys");

}  // namespace fire::wiimote
