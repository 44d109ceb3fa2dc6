#pragma once
// Wii Remote input reports that carry IR camera blobs (shared/wiimote-protocol.md), decoded and,
// for the simulated rig and the fake remote, encoded byte for byte. Report 0x33 (extended IR, 3 bytes
// per object) is what FIRE asks the device for; 0x36 and 0x37 (basic IR, two objects in 5 bytes) are
// decoded too. The one codec: the driver (platform/wiimote), tracking, live calibration and the live
// view all read slots through it, so an empty slot means the same everywhere.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace fire {

inline constexpr int kIrSlots = 4;
// Image size of the Wii Remote camera as reported (128 x 96 sensor with 8x sub-pixel interpolation).
inline constexpr int kWiimoteWidth = 1024;
inline constexpr int kWiimoteHeight = 768;
// A Wii Remote streams its reports at 100 Hz (measured 98.3 +- 4.0 Hz: shared/wiimote-protocol.md).
inline constexpr int64_t kReportPeriodUs = 10'000;
// Report lengths including the report id byte.
inline constexpr size_t kReport33Size = 18;  // id, 2 buttons, 3 accelerometer, 4 x 3 IR
inline constexpr size_t kReport36Size = 22;  // id, 2 buttons, 10 IR, 9 extension
inline constexpr size_t kReport37Size = 22;  // id, 2 buttons, 3 accelerometer, 10 IR, 6 extension

struct IrSlot {
  bool seen = false;
  uint16_t x = 0;    // 0..1023
  uint16_t y = 0;    // 0..767
  uint8_t size = 0;  // 0..15 in extended mode; basic mode carries none (0)
};
using IrSlots = std::array<IrSlot, kIrSlots>;

struct IrReport {
  uint8_t report_id = 0x33;
  std::array<uint8_t, 2> buttons{};  // as sent; their spare bits hold accelerometer low bits
  std::array<uint8_t, 3> accel{};    // 0x33 and 0x37 only
  IrSlots slots{};
};

enum class ReportStatus : uint8_t {
  Ok,         // an IR report; some slots may still have been dropped as out of range
  NotIr,      // a valid Wii Remote input report without IR data (acknowledgement, status, buttons only)
  Empty,      // no bytes (e.g. the hex of a log line was garbled)
  BadLength,  // an IR report id with fewer bytes than its layout (truncated)
  UnknownId,  // not a Wii Remote input report id
};

struct DecodedReport {
  ReportStatus status = ReportStatus::Empty;
  IrReport report;
  int out_of_range_slots = 0;  // slots whose coordinates no camera can produce: dropped, not seen
  size_t trailing_bytes = 0;   // bytes past the layout (clones, padding stacks): read past, as the kernel does
};

// The length of an IR report's layout, report id included; 0 for an id that carries no IR.
size_t ir_report_size(uint8_t id);

// Never fails hard: any byte sequence gives a status. A slot is empty, and not a blob, when it is
// the device's FF FF FF (y = 1023) or a fresh remote's 00 00 00 (x = y = 0, size 0: remotes that
// have not yet seen light report their slots so, and fix them one by one); any other y above 767 is
// counted as out of range and the slot dropped. A report longer than its layout is read for the
// layout's bytes; a shorter one is BadLength.
DecodedReport decode_ir_report(std::span<const uint8_t> bytes);
// The blobs a report shows: its seen slots; nothing for bytes that are not a readable IR report.
std::optional<int> ir_blob_count(std::span<const uint8_t> bytes);

// The exact bytes the device sends for `report` in its report_id's layout (0x33, 0x36 or 0x37;
// any other id gives an empty vector). Coordinates are clamped to the 10-bit fields; unseen slots
// are written as the device writes them (all ones). Extension bytes are zero.
std::vector<uint8_t> encode_ir_report(const IrReport& report);

}  // namespace fire
