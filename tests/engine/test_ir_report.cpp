// Wii Remote IR reports: byte layout per shared/wiimote-protocol.md, and what garbled input gives.
#include <catch2/catch.hpp>
#include <vector>

#include "engine/ir_report.hpp"

using namespace fire;

namespace {

IrReport report_with(uint8_t id, std::initializer_list<IrSlot> slots) {
  IrReport r;
  r.report_id = id;
  r.buttons = {0x12, 0x34};
  r.accel = {0x80, 0x81, 0x9A};
  size_t k = 0;
  for (const IrSlot& s : slots) r.slots[k++] = s;
  return r;
}

}  // namespace

TEST_CASE("report 0x33 packs each object as x = b0 | (b2 & 0x30) << 4, y = b1 | (b2 & 0xC0) << 2, size = b2 & 0x0F") {
  // x = 683 = 0x2AB, y = 461 = 0x1CD, size 5 -> AB CD 65; slot 2: x = 1023, y = 767, size 15 -> FF FF BF.
  const IrReport r = report_with(0x33, {{true, 683, 461, 5}, {}, {true, 1023, 767, 15}, {}});
  const std::vector<uint8_t> bytes = encode_ir_report(r);
  const std::vector<uint8_t> expected{0x33, 0x12, 0x34, 0x80, 0x81, 0x9A, 0xAB, 0xCD, 0x65, 0xFF, 0xFF, 0xFF,
                                      0xFF, 0xFF, 0xBF, 0xFF, 0xFF, 0xFF};
  CHECK(bytes == expected);
  const DecodedReport d = decode_ir_report(bytes);
  REQUIRE(d.status == ReportStatus::Ok);
  CHECK(d.out_of_range_slots == 0);
  CHECK(d.report.buttons == r.buttons);
  CHECK(d.report.accel == r.accel);
  CHECK(d.report.slots[0].seen);
  CHECK(d.report.slots[0].x == 683);
  CHECK(d.report.slots[0].y == 461);
  CHECK(d.report.slots[0].size == 5);
  CHECK_FALSE(d.report.slots[1].seen);
  CHECK(d.report.slots[2].x == 1023);
  CHECK(d.report.slots[2].y == 767);
  CHECK(d.report.slots[2].size == 15);
  CHECK_FALSE(d.report.slots[3].seen);
}

TEST_CASE("the input log format's example report decodes to no blobs") {
  // 40000 hid 0 3300006050e0ffffffffffffffffffffffff (engine/INPUT_LOG.md)
  const std::vector<uint8_t> bytes{0x33, 0x00, 0x00, 0x60, 0x50, 0xe0, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff,
                                   0xff, 0xff, 0xff, 0xff, 0xff, 0xff};
  const DecodedReport d = decode_ir_report(bytes);
  REQUIRE(d.status == ReportStatus::Ok);
  for (const IrSlot& s : d.report.slots) CHECK_FALSE(s.seen);
  CHECK(d.report.accel == std::array<uint8_t, 3>{0x60, 0x50, 0xe0});
}

TEST_CASE("basic-mode reports 0x36 and 0x37 pack two objects in five bytes") {
  // Pair 1: (683, 461) and (300, 700) -> AB CD 69 2C BC: b2 = 01 10 10 01 (y1 hi, x1 hi, y2 hi, x2 hi).
  const IrReport r = report_with(0x37, {{true, 683, 461, 0}, {true, 300, 700, 0}, {}, {true, 5, 6, 0}});
  const std::vector<uint8_t> bytes = encode_ir_report(r);
  REQUIRE(bytes.size() == kReport37Size);
  CHECK(bytes[6] == 0xAB);
  CHECK(bytes[7] == 0xCD);
  CHECK(bytes[8] == 0x69);
  CHECK(bytes[9] == 0x2C);
  CHECK(bytes[10] == 0xBC);
  for (uint8_t id : {uint8_t{0x36}, uint8_t{0x37}}) {
    IrReport in = r;
    in.report_id = id;
    const DecodedReport d = decode_ir_report(encode_ir_report(in));
    REQUIRE(d.status == ReportStatus::Ok);
    for (int k = 0; k < kIrSlots; ++k) {
      CHECK(d.report.slots[k].seen == r.slots[k].seen);
      if (r.slots[k].seen) {
        CHECK(d.report.slots[k].x == r.slots[k].x);
        CHECK(d.report.slots[k].y == r.slots[k].y);
      }
    }
    CHECK(d.report.buttons == r.buttons);
  }
}

TEST_CASE("garbled, truncated and foreign reports get a status, never a crash") {
  const std::vector<uint8_t> good = encode_ir_report(report_with(0x33, {{true, 10, 20, 3}}));
  SECTION("no bytes") { CHECK(decode_ir_report({}).status == ReportStatus::Empty); }
  SECTION("every truncation is named; a longer report is read for its layout's bytes, as the kernel reads it") {
    for (size_t n = 1; n < good.size(); ++n)
      CHECK(decode_ir_report(std::span(good.data(), n)).status == ReportStatus::BadLength);
    std::vector<uint8_t> longer = good;
    longer.insert(longer.end(), {0xFF, 0x00, 0x12, 0x34});  // a clone's padding
    const DecodedReport d = decode_ir_report(longer);
    REQUIRE(d.status == ReportStatus::Ok);
    CHECK(d.trailing_bytes == 4);
    CHECK(d.report.slots[0].seen);
    CHECK(d.report.slots[0].x == 10);
    CHECK(ir_blob_count(longer) == 1);
  }
  SECTION("ids no Wii Remote sends") {
    for (uint8_t id : {uint8_t{0x00}, uint8_t{0x11}, uint8_t{0x99}, uint8_t{0xFF}}) {
      std::vector<uint8_t> b = good;
      b[0] = id;
      CHECK(decode_ir_report(b).status == ReportStatus::UnknownId);
    }
  }
  SECTION("valid reports without IR data are skipped, not rejected") {
    for (uint8_t id : {uint8_t{0x20}, uint8_t{0x22}, uint8_t{0x30}, uint8_t{0x3F}})
      CHECK(decode_ir_report(std::vector<uint8_t>{id, 0, 0}).status == ReportStatus::NotIr);
  }
  SECTION("a y no camera reports drops that object only") {
    std::vector<uint8_t> b = good;
    // Slot 1: x = 5, y = 800 = 0x320 -> 05 20 C0 (y high bits 11); slot 2: y = 1023 with other bits (unseen marker).
    b[9] = 0x05;
    b[10] = 0x20;
    b[11] = 0xC0;
    b[12] = 0x07;
    b[13] = 0xFF;
    b[14] = 0xC2;
    const DecodedReport d = decode_ir_report(b);
    REQUIRE(d.status == ReportStatus::Ok);
    CHECK(d.out_of_range_slots == 1);
    CHECK(d.report.slots[0].seen);
    CHECK(d.report.slots[0].x == 10);
    CHECK_FALSE(d.report.slots[1].seen);
    CHECK_FALSE(d.report.slots[2].seen);
  }
  SECTION("every single-byte corruption of a good report decodes to a status") {
    for (size_t i = 0; i < good.size(); ++i)
      for (int v = 0; v < 256; v += 17) {
        std::vector<uint8_t> b = good;
        b[i] = static_cast<uint8_t>(v);
        const DecodedReport d = decode_ir_report(b);
        for (const IrSlot& s : d.report.slots)
          if (s.seen) CHECK((s.x < 1024 && s.y < 768));
      }
  }
}

TEST_CASE("a fresh remote's zero slots are empty, not blobs at the corner, while it fixes them one by one") {
  // Slot 0 lit, slots 1-3 still 00 00 00 (xwiimote #88), then slot 1 fixed to FF FF FF.
  std::vector<uint8_t> b{0x33, 0, 0, 0x80, 0x80, 0x80, 0x10, 0x20, 0x03, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  DecodedReport d = decode_ir_report(b);
  REQUIRE(d.status == ReportStatus::Ok);
  CHECK(d.report.slots[0].seen);
  for (int k = 1; k < kIrSlots; ++k) CHECK_FALSE(d.report.slots[k].seen);
  CHECK(ir_blob_count(b) == 1);
  std::fill(b.begin() + 9, b.begin() + 12, uint8_t{0xFF});
  CHECK(ir_blob_count(b) == 1);
  // A dark camera whose slots are all zeros shows no pen.
  std::fill(b.begin() + 6, b.end(), uint8_t{0});
  CHECK(ir_blob_count(b) == 0);
  // A blob at the corner with a size is still a blob; basic mode carries no size, so its zeros are empty.
  b[8] = 0x01;
  CHECK(ir_blob_count(b) == 1);
  std::vector<uint8_t> basic(kReport36Size, 0);
  basic[0] = 0x36;
  CHECK(ir_blob_count(basic) == 0);
}

TEST_CASE("encoding an unknown report id gives no bytes") {
  CHECK(encode_ir_report(report_with(0x30, {})).empty());
}
