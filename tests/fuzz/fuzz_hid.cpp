// Wii Remote report decoder: any bytes give a status; an IR report's slots are in the camera's range;
// decode -> encode -> decode gives the same report (the encoder writes what the decoder kept).
#include <cstdint>
#include <span>

#include "engine/ir_report.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace fire;

namespace {

bool same_report(const IrReport& a, const IrReport& b) {
  if (a.report_id != b.report_id || a.buttons != b.buttons || a.accel != b.accel) return false;
  for (int k = 0; k < kIrSlots; ++k) {
    const IrSlot &s = a.slots[k], &t = b.slots[k];
    if (s.seen != t.seen || (s.seen && (s.x != t.x || s.y != t.y || s.size != t.size))) return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::span<const uint8_t> bytes(data, size);
  const DecodedReport d = decode_ir_report(bytes);
  const bool ir_id = size > 0 && (data[0] == 0x33 || data[0] == 0x36 || data[0] == 0x37);
  FUZZ_CHECK((d.status == ReportStatus::Empty) == (size == 0), "Empty exactly for no bytes");
  if (d.status != ReportStatus::Ok) {
    FUZZ_CHECK(d.out_of_range_slots == 0, "only an IR report counts out-of-range slots");
    if (d.status == ReportStatus::BadLength) FUZZ_CHECK(ir_id, "BadLength only for IR report ids");
    return 0;
  }
  FUZZ_CHECK(ir_id, "Ok only for IR report ids");
  FUZZ_CHECK(d.out_of_range_slots >= 0 && d.out_of_range_slots <= kIrSlots, "out-of-range count within the slots");
  for (const IrSlot& s : d.report.slots)
    if (s.seen) {
      FUZZ_CHECK(s.x <= 1023 && s.y <= 767 && s.size <= 15, "a seen slot lies in the camera's range");
      FUZZ_CHECK(s.x != 0 || s.y != 0 || s.size != 0, "a fresh remote's zero slot is empty");
    }
  const std::vector<uint8_t> encoded = encode_ir_report(d.report);
  FUZZ_CHECK(encoded.size() + d.trailing_bytes == size, "the encoder writes the report id's length");
  const DecodedReport again = decode_ir_report(encoded);
  FUZZ_CHECK(again.status == ReportStatus::Ok && again.out_of_range_slots == 0, "an encoded report decodes cleanly");
  FUZZ_CHECK(same_report(d.report, again.report), "decode -> encode -> decode keeps the report");
  return 0;
}
