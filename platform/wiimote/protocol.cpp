#include "platform/wiimote/protocol.hpp"

#include <algorithm>

namespace fire::wiimote {

bool is_wii_remote(uint16_t vendor, uint16_t product, std::string_view product_name) {
  if (vendor != kNintendoVendor || (product != kProductRemote && product != kProductRemotePlus)) return false;
  if (product_name.empty()) return true;
  // hidapi gives "Nintendo RVL-CNT-01", the kernel's HID_NAME the same; some stacks drop the maker.
  for (std::string_view model : {"RVL-CNT-01", "RVL-CNT-01-TR"})
    if (product_name == model || product_name == "Nintendo " + std::string(model)) return true;
  return false;
}

SensitivityBlocks sensitivity_blocks(int level) {
  switch (level) {
    case 1: return {{0x02, 0x00, 0x00, 0x71, 0x01, 0x00, 0x64, 0x00, 0xFE}, {0xFD, 0x05}};
    case 2: return {{0x02, 0x00, 0x00, 0x71, 0x01, 0x00, 0x96, 0x00, 0xB4}, {0xB3, 0x04}};
    case 4: return {{0x02, 0x00, 0x00, 0x71, 0x01, 0x00, 0xC8, 0x00, 0x36}, {0x35, 0x03}};
    case 5: return {{0x07, 0x00, 0x00, 0x71, 0x01, 0x00, 0x72, 0x00, 0x20}, {0x1F, 0x03}};
    case kHighSensitivity: return {{0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x90, 0x00, 0x41}, {0x40, 0x00}};
    default: return {{0x02, 0x00, 0x00, 0x71, 0x01, 0x00, 0xAA, 0x00, 0x64}, {0x63, 0x03}};
  }
}

Bytes leds_report(uint8_t leds, bool ack) {
  return {kOutLeds, static_cast<uint8_t>((leds & kLedBits) | (ack ? kAckRequestBit : 0))};
}

Bytes reporting_mode_report(uint8_t mode, bool continuous, bool ack) {
  return {kOutReportingMode, static_cast<uint8_t>((continuous ? kEnableBit : 0) | (ack ? kAckRequestBit : 0)), mode};
}

Bytes ir_pixel_clock_report(bool ack) {
  return {kOutIrPixelClock, static_cast<uint8_t>(kEnableBit | (ack ? kAckRequestBit : 0))};
}

Bytes ir_logic_report(bool ack) { return {kOutIrLogic, static_cast<uint8_t>(kEnableBit | (ack ? kAckRequestBit : 0))}; }

Bytes status_request_report() { return {kOutStatusRequest, 0x00}; }

Bytes write_register_report(uint32_t address, std::span<const uint8_t> data) {
  const size_t n = std::min<size_t>(data.size(), 16);
  Bytes out(22, 0);
  out[0] = kOutWriteMemory;
  out[1] = kEnableBit;
  out[2] = static_cast<uint8_t>(address >> 16);
  out[3] = static_cast<uint8_t>(address >> 8);
  out[4] = static_cast<uint8_t>(address);
  out[5] = static_cast<uint8_t>(n);
  std::copy_n(data.begin(), n, out.begin() + 6);
  return out;
}

size_t input_report_size(uint8_t id) {
  switch (id) {
    case 0x20: return 7;
    case 0x21: return 22;
    case 0x22: return 5;
    case 0x30: return 3;
    case 0x31: return 6;
    case 0x32: return 11;
    case 0x33: return 18;
    case 0x34: case 0x35: case 0x36: case 0x37: case 0x3D: case 0x3E: case 0x3F: return 22;
    default: return 0;
  }
}

std::optional<Ack> parse_ack(std::span<const uint8_t> report) {
  if (report.size() < input_report_size(kInAck) || report[0] != kInAck) return std::nullopt;
  return Ack{.report_id = report[3], .error = report[4]};
}

std::optional<StatusReport> parse_status(std::span<const uint8_t> report) {
  if (report.size() < input_report_size(kInStatus) || report[0] != kInStatus) return std::nullopt;
  return StatusReport{.flags = report[3], .battery = report[6]};
}

int battery_percent(const StatusReport& status) { return std::min(100, status.battery * 100 / kBatteryFull); }

std::optional<uint16_t> core_buttons(std::span<const uint8_t> report) {
  if (report.empty()) return std::nullopt;
  const uint8_t id = report[0];
  const bool carries = (id >= 0x20 && id <= 0x22) || (id >= 0x30 && id <= 0x37) || id == 0x3E || id == 0x3F;
  if (!carries || report.size() < input_report_size(id)) return std::nullopt;
  return static_cast<uint16_t>((report[1] << 8 | report[2]) & kAllButtons);
}

}  // namespace fire::wiimote
