#pragma once
// How the Wii Remote driver reaches devices: a backend enumerates and opens them, a device
// writes and reads raw reports. Two backends implement it: hidapi (hidapi_backend.hpp) for the
// real remotes and the fake bus (fake_remote.hpp) for tests and simulations.
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "engine/common.hpp"
#include "platform/wiimote/protocol.hpp"

namespace fire::wiimote {

// Nanoseconds on a monotonic clock. Injected everywhere so tests run faster than real time.
using Clock = std::function<int64_t()>;
// The host's steady clock.
Clock system_clock();

struct DeviceInfo {
  uint16_t vendor = 0;
  uint16_t product = 0;
  std::string serial;  // a Bluetooth remote's address, as the backend reports it
  std::string path;    // what open() takes
  std::string product_name{};  // as the device names itself (hidapi's product string); empty where not given
};
// A Wii Remote by its ids and, where given, its name: only these take camera and pad roles.
inline bool is_wii_remote(const DeviceInfo& info) { return is_wii_remote(info.vendor, info.product, info.product_name); }

// "00:1f:32:aa:bb:cc" and "001F32AABBCC" both give "00:1F:32:AA:BB:CC"; anything that is not
// twelve hex digits (with or without separators) is returned unchanged.
std::string normalize_address(const std::string& serial);

enum class ReadStatus : uint8_t { Report, Timeout, Gone };

struct ReadResult {
  ReadStatus status = ReadStatus::Timeout;
  Bytes report;       // Report: report id first
  std::string error;  // Gone: why
};

// One open device. Closing is destruction. A device may be used by one thread at a time.
class Device {
 public:
  virtual ~Device() = default;
  // Writes one output report, report id first. Fails when the device is gone or refuses it.
  virtual Status write(std::span<const uint8_t> report) = 0;
  // Waits up to timeout_ms (0: does not wait) for one input report.
  virtual ReadResult read(int timeout_ms) = 0;
};

class Backend {
 public:
  virtual ~Backend() = default;
  // Every HID device the backend sees, Wii Remote or not; fails only when the bus cannot be read.
  virtual Result<std::vector<DeviceInfo>> enumerate() = 0;
  // Errors name the device and, where the user can fix it, how.
  virtual Result<std::unique_ptr<Device>> open(const DeviceInfo& info) = 0;
};

}  // namespace fire::wiimote
