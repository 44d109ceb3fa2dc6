#pragma once
// Wii Remote input reports that carry IR camera blobs (shared/wiimote-protocol.md), decoded and,
// for the simulated rig, encoded byte for byte. Report 0x33 (extended IR, 3 bytes per object) is
// what FIRE asks the device for; 0x36 and 0x37 (basic IR, two objects in 5 bytes) are decoded too.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace fire::tracking {

inline constexpr int kIrSlots = 4;
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

struct IrReport {
  uint8_t report_id = 0x33;
  std::array<uint8_t, 2> buttons{};  // as sent; their spare bits hold accelerometer low bits
  std::array<uint8_t, 3> accel{};    // 0x33 and 0x37 only
  std::array<IrSlot, kIrSlots> slots{};
};

enum class ReportStatus : uint8_t {
  Ok,         // an IR report; some slots may still have been dropped as out of range
  NotIr,      // a valid Wii Remote input report without IR data (acknowledgement, status, buttons only)
  Empty,      // no bytes (e.g. the hex of a log line was garbled)
  BadLength,  // an IR report id with the wrong number of bytes (truncated or padded)
  UnknownId,  // not a Wii Remote input report id
};

struct DecodedReport {
  ReportStatus status = ReportStatus::Empty;
  IrReport report;
  int out_of_range_slots = 0;  // slots whose coordinates no camera can produce: dropped, not seen
};

// Never fails hard: any byte sequence gives a status. An empty slot is the device's FF FF FF
// (y = 1023); any other y above 767 is counted as out of range and the slot dropped.
DecodedReport decode_ir_report(std::span<const uint8_t> bytes);

// The exact bytes the device sends for `report` in its report_id's layout (0x33, 0x36 or 0x37;
// any other id gives an empty vector). Coordinates are clamped to the 10-bit fields; unseen slots
// are written as the device writes them (all ones). Extension bytes are zero.
std::vector<uint8_t> encode_ir_report(const IrReport& report);

// Per-category counts of what a stream of reports held.
struct ReportCounts {
  size_t ir_reports = 0;          // decoded IR reports (0x33, 0x36, 0x37)
  size_t not_ir = 0;              // valid reports without IR data, skipped
  size_t garbled = 0;             // hex that did not parse, or no bytes at all
  size_t bad_length = 0;          // truncated or padded IR reports
  size_t unknown_id = 0;          // report ids no Wii Remote sends
  size_t unknown_device = 0;      // devices that are no camera: not 0 or 1 in a log without device records,
                                  // or with no camera role in the log's `meta device` records
  size_t pad_reports = 0;         // reports of the command pad (role `pad` in `meta device`): no camera data
  size_t bad_device_records = 0;  // `meta device` records that do not read as D ADDRESS ROLE PRODUCT, or whose
                                  // product is no Wii Remote's (0306, 0330): their device is no camera
  size_t out_of_range_slots = 0;  // blobs with impossible coordinates, dropped from kept reports
  size_t rejected_reports() const { return garbled + bad_length + unknown_id + unknown_device; }
};

}  // namespace fire::tracking
