#pragma once
// What stands between a paired remote and FIRE on Linux, found from sysfs, and the commands that
// fix it (docs/wiimote.md explains them). Kept apart from the hidapi backend so tests can run it
// on a made-up sysfs tree.
#include <optional>
#include <string>

namespace fire::wiimote {

// The udev rule FIRE ships, and the command that installs it, from the source tree's root.
inline constexpr const char* kUdevRule = "platform/wiimote/99-fire-wiimote.rules";
std::string udev_install_command();
// For a device the user may not open.
std::string permission_advice(const std::string& path);

struct KernelBinding {
  std::string hid_id;  // the HID device behind the hidraw node, e.g. 0005:057E:0306.0003
  std::string driver;  // the kernel driver bound to it; "wiimote" is hid-wiimote
};
inline constexpr const char* kKernelWiimoteDriver = "wiimote";

// The HID device behind a hidraw node (/dev/hidrawN) and its bound driver, read from
// <sysfs_root>/class/hidraw/hidrawN/device; nullopt when sysfs does not say.
std::optional<KernelBinding> kernel_binding(const std::string& hidraw_path, const std::string& sysfs_root = "/sys");
// How to take the remote from hid-wiimote, which sends its own reporting modes beside FIRE.
std::string unbind_advice(const KernelBinding& binding);

}  // namespace fire::wiimote
