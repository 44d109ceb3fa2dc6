#include "engine/ir_report.hpp"

#include <algorithm>

namespace fire {
namespace {

constexpr uint16_t kUnseenCoordinate = 1023;

// Input reports a Wii Remote sends that FIRE does not read IR from: status 0x20, memory read
// 0x21, acknowledgement 0x22, the button/accelerometer/extension modes, and the interleaved
// full-IR pair 0x3E/0x3F (camera mode 5, which FIRE never requests).
bool is_non_ir_report(uint8_t id) {
  switch (id) {
    case 0x20: case 0x21: case 0x22: case 0x30: case 0x31: case 0x32: case 0x34: case 0x35:
    case 0x3D: case 0x3E: case 0x3F:
      return true;
    default:
      return false;
  }
}

// Shared by both modes: a slot is unseen when y reads 1023 (the device's all-ones marker) or when
// it is a fresh remote's zeros.
void set_slot(IrSlot& slot, uint16_t x, uint16_t y, uint8_t size, int& out_of_range) {
  if (y == kUnseenCoordinate || (x == 0 && y == 0 && size == 0)) return;
  if (y >= kWiimoteHeight) {
    ++out_of_range;
    return;
  }
  slot = IrSlot{.seen = true, .x = x, .y = y, .size = size};
}

void decode_extended(std::span<const uint8_t, 12> ir, DecodedReport& out) {
  for (int k = 0; k < kIrSlots; ++k) {
    const uint8_t b0 = ir[3 * k], b1 = ir[3 * k + 1], b2 = ir[3 * k + 2];
    const uint16_t x = static_cast<uint16_t>(b0 | ((b2 & 0x30) << 4));
    const uint16_t y = static_cast<uint16_t>(b1 | ((b2 & 0xC0) << 2));
    set_slot(out.report.slots[k], x, y, static_cast<uint8_t>(b2 & 0x0F), out.out_of_range_slots);
  }
}

void decode_basic(std::span<const uint8_t, 10> ir, DecodedReport& out) {
  for (int pair = 0; pair < 2; ++pair) {
    const uint8_t* b = ir.data() + 5 * pair;
    const uint16_t x1 = static_cast<uint16_t>(b[0] | ((b[2] & 0x30) << 4));
    const uint16_t y1 = static_cast<uint16_t>(b[1] | ((b[2] & 0xC0) << 2));
    const uint16_t x2 = static_cast<uint16_t>(b[3] | ((b[2] & 0x03) << 8));
    const uint16_t y2 = static_cast<uint16_t>(b[4] | ((b[2] & 0x0C) << 6));
    set_slot(out.report.slots[2 * pair], x1, y1, 0, out.out_of_range_slots);
    set_slot(out.report.slots[2 * pair + 1], x2, y2, 0, out.out_of_range_slots);
  }
}

uint16_t field_x(const IrSlot& s) { return s.seen ? std::min<uint16_t>(s.x, 1023) : kUnseenCoordinate; }
uint16_t field_y(const IrSlot& s) { return s.seen ? std::min<uint16_t>(s.y, 1023) : kUnseenCoordinate; }

}  // namespace

size_t ir_report_size(uint8_t id) {
  switch (id) {
    case 0x33: return kReport33Size;
    case 0x36: return kReport36Size;
    case 0x37: return kReport37Size;
    default: return 0;
  }
}

DecodedReport decode_ir_report(std::span<const uint8_t> bytes) {
  DecodedReport out;
  if (bytes.empty()) return out;
  const uint8_t id = bytes[0];
  out.report.report_id = id;
  if (is_non_ir_report(id)) {
    out.status = ReportStatus::NotIr;
    return out;
  }
  const size_t expected = ir_report_size(id);
  if (expected == 0) {
    out.status = ReportStatus::UnknownId;
    return out;
  }
  if (bytes.size() < expected) {
    out.status = ReportStatus::BadLength;
    return out;
  }
  out.status = ReportStatus::Ok;
  out.trailing_bytes = bytes.size() - expected;
  out.report.buttons = {bytes[1], bytes[2]};
  if (id == 0x36) {
    decode_basic(bytes.subspan<3, 10>(), out);
  } else {
    out.report.accel = {bytes[3], bytes[4], bytes[5]};
    if (id == 0x33)
      decode_extended(bytes.subspan<6, 12>(), out);
    else
      decode_basic(bytes.subspan<6, 10>(), out);
  }
  return out;
}

std::optional<int> ir_blob_count(std::span<const uint8_t> bytes) {
  const DecodedReport d = decode_ir_report(bytes);
  if (d.status != ReportStatus::Ok) return std::nullopt;
  int n = 0;
  for (const IrSlot& s : d.report.slots) n += s.seen;
  return n;
}

std::vector<uint8_t> encode_ir_report(const IrReport& report) {
  const uint8_t id = report.report_id;
  if (ir_report_size(id) == 0) return {};
  std::vector<uint8_t> out(ir_report_size(id), 0);
  out[0] = id;
  out[1] = report.buttons[0];
  out[2] = report.buttons[1];
  size_t ir = 3;
  if (id != 0x36) {
    std::copy(report.accel.begin(), report.accel.end(), out.begin() + 3);
    ir = 6;
  }
  if (id == 0x33) {
    for (int k = 0; k < kIrSlots; ++k) {
      const IrSlot& s = report.slots[k];
      const uint16_t x = field_x(s), y = field_y(s);
      const uint8_t size = s.seen ? static_cast<uint8_t>(s.size & 0x0F) : 0x0F;
      out[ir + 3 * k] = static_cast<uint8_t>(x & 0xFF);
      out[ir + 3 * k + 1] = static_cast<uint8_t>(y & 0xFF);
      out[ir + 3 * k + 2] = static_cast<uint8_t>(((y >> 8) & 0x03) << 6 | ((x >> 8) & 0x03) << 4 | size);
    }
  } else {
    for (int pair = 0; pair < 2; ++pair) {
      const IrSlot& s1 = report.slots[2 * pair];
      const IrSlot& s2 = report.slots[2 * pair + 1];
      const uint16_t x1 = field_x(s1), y1 = field_y(s1), x2 = field_x(s2), y2 = field_y(s2);
      uint8_t* b = out.data() + ir + 5 * pair;
      b[0] = static_cast<uint8_t>(x1 & 0xFF);
      b[1] = static_cast<uint8_t>(y1 & 0xFF);
      b[2] = static_cast<uint8_t>(((y1 >> 8) & 0x03) << 6 | ((x1 >> 8) & 0x03) << 4 | ((y2 >> 8) & 0x03) << 2 |
                                  ((x2 >> 8) & 0x03));
      b[3] = static_cast<uint8_t>(x2 & 0xFF);
      b[4] = static_cast<uint8_t>(y2 & 0xFF);
    }
  }
  return out;
}

}  // namespace fire
