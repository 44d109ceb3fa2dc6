#pragma once
// The real remotes through hidapi's hidraw backend (Debian libhidapi-dev, pkg-config
// hidapi-hidraw). Linked only by what talks to hardware (`fire devices`, a live session).
#include "platform/wiimote/device.hpp"

namespace fire::wiimote {

class HidapiBackend : public Backend {
 public:
  HidapiBackend();
  ~HidapiBackend() override;
  HidapiBackend(const HidapiBackend&) = delete;
  HidapiBackend& operator=(const HidapiBackend&) = delete;

  // Nintendo's HID devices (vendor 0x057E), Wii Remotes or not.
  Result<std::vector<DeviceInfo>> enumerate() override;
  // Refuses, and says what to do, a device the user may not open or one the kernel's
  // hid-wiimote driver holds.
  Result<std::unique_ptr<Device>> open(const DeviceInfo& info) override;

 private:
  bool initialised_ = false;
};

}  // namespace fire::wiimote
