#pragma once
// The few Wii Remote reports the driver writes and reads (shared/wiimote-protocol.md): output
// reports, acknowledgements, status reports and buttons. IR reports are read with the one codec,
// engine/ir_report.hpp. Every parser accepts any byte sequence; a report longer than its layout is
// read for the layout's bytes, as the kernel reads it.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "engine/ir_report.hpp"

namespace fire::wiimote {

using Bytes = std::vector<uint8_t>;

inline constexpr uint16_t kNintendoVendor = 0x057E;
inline constexpr uint16_t kProductRemote = 0x0306;      // the original Wii Remote
inline constexpr uint16_t kProductRemotePlus = 0x0330;  // Wii Remote Plus (-TR)
// The ids are shared with the Wii U Pro Controller (RVL-CNT-01-UC) and the Balance Board
// (RVL-WBC-01), so where the backend gives the product name it must be a Wii Remote's (RVL-CNT-01 or
// RVL-CNT-01-TR); an empty name is not known and the ids decide.
bool is_wii_remote(uint16_t vendor, uint16_t product, std::string_view product_name = {});

// Output report ids.
inline constexpr uint8_t kOutLeds = 0x11;
inline constexpr uint8_t kOutReportingMode = 0x12;
inline constexpr uint8_t kOutIrPixelClock = 0x13;
inline constexpr uint8_t kOutStatusRequest = 0x15;
inline constexpr uint8_t kOutWriteMemory = 0x16;
inline constexpr uint8_t kOutIrLogic = 0x1A;
// Input report ids.
inline constexpr uint8_t kInStatus = 0x20;
inline constexpr uint8_t kInAck = 0x22;
inline constexpr uint8_t kInButtons = 0x30;
inline constexpr uint8_t kInIrExtended = 0x33;

// Bits of the first payload byte of an output report.
inline constexpr uint8_t kRumbleBit = 0x01;
inline constexpr uint8_t kAckRequestBit = 0x02;  // 0x11-0x14, 0x19, 0x1A: acknowledge this report
inline constexpr uint8_t kEnableBit = 0x04;      // 0x13/0x1A: on; 0x12: continuous; 0x16: registers
inline constexpr uint8_t kLedBits = 0xF0;
// The LED bit of player n (1..4).
constexpr uint8_t player_led(int n) { return static_cast<uint8_t>(0x10 << (n - 1)); }

// IR camera registers.
inline constexpr uint32_t kRegIrControl = 0xB00030;
inline constexpr uint32_t kRegIrBlock1 = 0xB00000;
inline constexpr uint32_t kRegIrBlock2 = 0xB0001A;
inline constexpr uint32_t kRegIrMode = 0xB00033;
inline constexpr uint8_t kIrControlEnable = 0x08;
inline constexpr uint8_t kIrModeExtended = 3;  // 3 bytes per object, read by report 0x33

// Sensitivity 1..5 are the Wii's levels; kHighSensitivity is the community's high setting.
inline constexpr int kHighSensitivity = 6;
struct SensitivityBlocks {
  std::array<uint8_t, 9> block1;
  std::array<uint8_t, 2> block2;
};
// Levels outside 1..kHighSensitivity give level 3, the kernel's default.
SensitivityBlocks sensitivity_blocks(int level);

// Output reports; the rumble bit is left clear (the driver sets it per remote when it writes).
Bytes leds_report(uint8_t leds, bool ack);
Bytes reporting_mode_report(uint8_t mode, bool continuous, bool ack);
Bytes ir_pixel_clock_report(bool ack);
Bytes ir_logic_report(bool ack);
Bytes status_request_report();
// Writes 1..16 bytes to a register address; a memory write is always acknowledged.
Bytes write_register_report(uint32_t address, std::span<const uint8_t> data);

// Input report length including the id, or 0 for an id no Wii Remote sends.
size_t input_report_size(uint8_t id);
// A data report (0x30-0x3F): what the reporting mode streams.
inline bool is_data_report(uint8_t id) { return id >= 0x30 && id <= 0x3F; }

struct Ack {
  uint8_t report_id = 0;
  uint8_t error = 0;
};
// Acknowledgement error codes the driver acts on (the kernel's hid-wiimote and Dolphin).
inline constexpr uint8_t kAckBusy = 4;         // try the same report again a little later
inline constexpr uint8_t kAckNoCamera = 7;     // a camera register written while the camera is off
std::optional<Ack> parse_ack(std::span<const uint8_t> report);

inline constexpr uint8_t kStatusBatteryLow = 0x01, kStatusExtension = 0x02, kStatusCameraOn = 0x08;
struct StatusReport {
  uint8_t flags = 0;    // 0x01 battery low, 0x02 extension, 0x04 speaker, 0x08 IR camera on, LEDs in 0xF0
  uint8_t battery = 0;  // the raw level; kBatteryFull is a fresh pair of cells
  bool battery_low() const { return flags & kStatusBatteryLow; }
  bool camera_on() const { return flags & kStatusCameraOn; }
};
inline constexpr uint8_t kBatteryFull = 0xC8;
std::optional<StatusReport> parse_status(std::span<const uint8_t> report);
// Percent of a full battery (fresher cells than kBatteryFull read 100).
int battery_percent(const StatusReport& status);

// The core buttons, as the first two payload bytes of the reports that carry them (0x20-0x22, and the
// data reports 0x30-0x37, 0x3E, 0x3F) hold them, first byte high (wiibrew.org, "Core Buttons").
inline constexpr uint16_t kButtonLeft = 0x0100, kButtonRight = 0x0200, kButtonDown = 0x0400, kButtonUp = 0x0800,
                          kButtonPlus = 0x1000, kButtonTwo = 0x0001, kButtonOne = 0x0002, kButtonB = 0x0004,
                          kButtonA = 0x0008, kButtonMinus = 0x0010, kButtonHome = 0x0080;
inline constexpr uint16_t kAllButtons = 0x1F9F;
// The buttons held when `report` was sent; nullopt for a report that does not carry them or is too short.
std::optional<uint16_t> core_buttons(std::span<const uint8_t> report);

}  // namespace fire::wiimote
