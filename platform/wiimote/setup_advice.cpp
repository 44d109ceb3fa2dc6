#include "platform/wiimote/setup_advice.hpp"

#include <filesystem>
#include <system_error>

namespace fire::wiimote {

std::string udev_install_command() {
  return std::string("sudo install -m 644 ") + kUdevRule +
         " /etc/udev/rules.d/ && sudo udevadm control --reload-rules && sudo udevadm trigger";
}

std::string permission_advice(const std::string& path) {
  return "permission denied on " + path + ": install FIRE's udev rule (" + udev_install_command() +
         "), then switch the remote off and on (docs/wiimote.md)";
}

std::optional<KernelBinding> kernel_binding(const std::string& hidraw_path, const std::string& sysfs_root) {
  namespace fs = std::filesystem;
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
  return "the kernel's hid-wiimote driver is bound to " + b.hid_id +
         " and changes the reporting mode behind FIRE's back. Take the remote from it: " +
         "echo -n " + b.hid_id + " | sudo tee /sys/bus/hid/drivers/wiimote/unbind; echo -n " + b.hid_id +
         " | sudo tee /sys/bus/hid/drivers/hid-generic/bind; or for good: " +
         "echo 'blacklist hid_wiimote' | sudo tee /etc/modprobe.d/fire-wiimote.conf && sudo modprobe -r hid_wiimote, "
         "then switch the remote off and on (docs/wiimote.md)";
}

}  // namespace fire::wiimote
