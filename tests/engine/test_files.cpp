// The curve network file, the input log and the OBJ reader: exact round trips and clear refusals.
#include <catch2/catch.hpp>

#include "engine/input_log.hpp"
#include "engine/network_io.hpp"
#include "platform/obj.hpp"
#include "test_helpers.hpp"

using namespace fire;
using namespace fire::test;
using Catch::Matchers::Contains;

TEST_CASE("network file round-trips exactly", "[files]") {
  EditHistory h;
  Mesh m = square(&h);
  REQUIRE(h.apply(m, split(0, {0, 2}, {2, 2}, {{0.5, 0, 0}, {0.1 + 0.2, 0.3333333333333333, 1e-300}, {0.5, 1, 0}})).ok());
  m.compact();
  std::string text = network_to_json(m);
  auto back = network_from_json(text, "net.json");
  REQUIRE(back.ok());
  CHECK(back->same_pools(m));
  CHECK(back->hash() == m.hash());
  CHECK(network_to_json(*back) == text);
}

TEST_CASE("corrupt network files are refused with the file and the problem", "[files][reject]") {
  Mesh m = square();
  m.compact();
  const std::string good = network_to_json(m);
  auto refuse = [](const std::string& text, const char* part) {
    auto r = network_from_json(text, "bad.fnet");
    REQUIRE_FALSE(r.ok());
    CHECK_THAT(r.error(), Contains("bad.fnet"));
    CHECK_THAT(r.error(), Contains(part));
  };
  refuse(good.substr(0, good.size() / 2), "truncated or corrupt");
  refuse("", "not valid JSON");
  refuse("[1,2,3]", "not a FIRE curve network");
  std::string v2 = good;
  v2.replace(v2.find("\"version\":1"), 11, "\"version\":7");
  refuse(v2, "unsupported network version 7");
  std::string with_null = good;
  with_null.replace(with_null.find("[0.0,0.0,0.0]"), 13, "[null,0.0,0.0]");
  refuse(with_null, "not a number");
  std::string broken_loop = good;
  broken_loop.replace(broken_loop.find("\"edges\":[0,1,2,3]"), 17, "\"edges\":[0,2,1,3]");
  refuse(broken_loop, "face 0");
  std::string bad_index = good;
  bad_index.replace(bad_index.find("\"v\":[0,1]"), 9, "\"v\":[0,9]");
  refuse(bad_index, "edge 0 vertex is not an index below 4");
}

TEST_CASE("input log: every kind parses and formats back", "[files]") {
  std::string text =
      "FIRE-LOG 1\n# comment\n\n0 meta scene a dome\n5 down\n10 pen 0.1 -2 3e-5\n20 up\n30 cmd undo\n31 cmd redo\n"
      "32 cmd close\n40 cmd delete 1 2 3\n50 hid 1 33000102\n60 truth pen 1 2 3\n";
  auto log = parse_input_log(text, "a.log");
  REQUIRE(log.ok());
  REQUIRE(log->events.size() == 10);
  CHECK(log->events[2].p == Vec3(0.1, -2, 3e-5));
  CHECK(log->events[2].line == 6);
  CHECK(log->events[8].bytes == std::vector<uint8_t>{0x33, 0x00, 0x01, 0x02});
  CHECK(log->events[8].device == 1);
  CHECK(log->events[9].values == std::vector<double>{1, 2, 3});
  CHECK(log->events[0].text == "a dome");
  auto again = parse_input_log(format_input_log(log->events), "b.log");
  REQUIRE(again.ok());
  CHECK(format_input_log(again->events) == format_input_log(log->events));
}

TEST_CASE("input log: a pen sample's snap radius reads and formats back, without one it is 0", "[files]") {
  auto log = parse_input_log("FIRE-LOG 1\n10 pen 1 2 3 0.0125\n20 pen 1 2 3\n", "a.log");
  REQUIRE(log.ok());
  CHECK(log->events[0].p == Vec3(1, 2, 3));
  CHECK(log->events[0].snap == 0.0125);
  CHECK(log->events[1].snap == 0);
  CHECK(format_event(log->events[0]) == "10 pen 1 2 3 0.0125\n");
  CHECK(format_event(log->events[1]) == "20 pen 1 2 3\n");
}

TEST_CASE("input log: truncated, unknown version and malformed lines are refused", "[files][reject]") {
  auto refuse = [](const std::string& text, const char* part) {
    auto r = parse_input_log(text, "s.log");
    REQUIRE_FALSE(r.ok());
    CHECK_THAT(r.error(), Contains("s.log"));
    CHECK_THAT(r.error(), Contains(part));
  };
  refuse("FIRE-LOG 1\n0 down\n10 pen 1 2", "truncated");
  refuse("FIRE-LOG 4\n", "unknown input log version '4' (this build reads versions 1 to 3)");
  for (uint32_t version : {1u, 2u, 3u}) {
    auto read = parse_input_log("FIRE-LOG " + std::to_string(version) + "\n0 down\n", "v.log");
    REQUIRE(read.ok());
    CHECK(read->version == version);
  }
  refuse("hello\n", "not a FIRE input log");
  refuse("", "empty");
  refuse("FIRE-LOG 1\n10 pen 1 2\n", "pen needs three numbers");
  refuse("FIRE-LOG 1\n10 pen 1 2 x\n", "pen needs three numbers");
  refuse("FIRE-LOG 1\n10 pen 1 2 3 0\n", "snap radius must be a positive finite number");
  refuse("FIRE-LOG 1\n10 pen 1 2 3 -1\n", "snap radius must be a positive finite number");
  refuse("FIRE-LOG 1\n10 pen 1 2 3 inf\n", "snap radius must be a positive finite number");
  refuse("FIRE-LOG 1\n10 pen 1 2 3 4 5\n", "pen needs three numbers");
  refuse("FIRE-LOG 1\n10 fly\n", "unknown event kind 'fly'");
  refuse("FIRE-LOG 1\n10 down\n5 up\n", "back in time");
  refuse("FIRE-LOG 1\n10 hid 0 3300\n5 up\n", "back in time");
  refuse("FIRE-LOG 1\nabc down\n", "bad timestamp");
  refuse("FIRE-LOG 1\n10 cmd jump\n", "unknown command");
  refuse("FIRE-LOG 1\n10 cmd measure\n", "cmd measure needs the mark's number (0 or more) and nothing else");
  refuse("FIRE-LOG 1\n10 cmd measure 2 0 0 0\n", "cmd measure needs the mark's number");
  refuse("FIRE-LOG 1\n10 cmd measure -1\n", "cmd measure needs the mark's number");
  refuse("FIRE-LOG 1\n10 cmd mark 3 0.1 0.2\n", "cmd mark needs the mark's number (0 or more), then its finite object coordinates");
  refuse("FIRE-LOG 1\n10 cmd mark x\n", "cmd mark needs the mark's number");
  refuse("FIRE-LOG 1\n10 cmd mark 3 nan 0 0\n", "cmd mark needs the mark's number");
  refuse("FIRE-LOG 1\n10 cmd table 1\n", "cmd table takes no fields");
}

TEST_CASE("input log: marks measured by touch read and format back: cmd table, cmd measure N, cmd mark N", "[files]") {
  const std::string text = "FIRE-LOG 2\n10 cmd table\n20 cmd measure 4\n30 cmd mark 4\n40 cmd mark 4 0.5 0 1\n";
  auto log = parse_input_log(text, "m.log");
  REQUIRE(log.ok());
  REQUIRE(log->events.size() == 4);
  CHECK(log->events[0].command == CommandKind::Table);
  CHECK(log->events[1].command == CommandKind::Measure);
  CHECK(log->events[1].mark == 4);
  CHECK(log->events[2].command == CommandKind::MarkMeasured);
  CHECK(log->events[2].mark == 4);
  CHECK(log->events[3].command == CommandKind::Mark);
  CHECK(log->events[3].p == Vec3(0.5, 0, 1));
  for (const InputEvent& e : log->events) CHECK(is_touch_command(e.command));
  CHECK(format_input_log(log->events, log->version) == "FIRE-LOG 2\n10 cmd table\n20 cmd measure 4\n30 cmd mark 4\n40 cmd mark 4 0.5 0 1\n");
}

TEST_CASE("input log: a garbled device report is counted, not fatal", "[files]") {
  auto log = parse_input_log("FIRE-LOG 1\n0 hid 0 33zz\n1 hid 0 330\n2 down\n", "g.log");
  REQUIRE(log.ok());
  CHECK(log->rejected_hid_lines == 2);
  CHECK_FALSE(log->events[0].hid_ok);
  CHECK(log->events.size() == 3);
}

TEST_CASE("input log: a device report stamped back in time is kept and counted, the order stays the later lines'", "[files]") {
  auto log = parse_input_log("FIRE-LOG 1\n10 hid 0 3300\n20 hid 1 3300\n15 hid 0 3300\n20 down\n", "b.log");
  REQUIRE(log.ok());
  CHECK(log->hid_back_in_time == 1);
  REQUIRE(log->events.size() == 4);
  CHECK(log->events[2].t_us == 15);
  // The next line is checked against the last in-order line (20), not the late report.
  CHECK_FALSE(parse_input_log("FIRE-LOG 1\n20 hid 0 3300\n15 hid 0 3300\n17 down\n", "c.log").ok());
}

TEST_CASE("OBJ reader: faces with texture/normal indices, and refusals", "[files]") {
  auto ok = parse_obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 -1//1\n", "q.obj");
  REQUIRE(ok.ok());
  CHECK(ok->face_count() == 1);
  CHECK(ok->face_size(0) == 4);
  CHECK(ok->face_vertices[3] == 3);
  auto refuse = [](const std::string& text, const char* part) {
    auto r = parse_obj(text, "m.obj");
    REQUIRE_FALSE(r.ok());
    CHECK_THAT(r.error(), Contains("m.obj"));
    CHECK_THAT(r.error(), Contains(part));
  };
  refuse("", "no vertices");
  refuse("v 0 0 0\nv 1 0 0\nv 1 1 0\n", "no faces");
  refuse("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2", "at least 3 vertices");
  refuse("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 7\n", "out of range");
  refuse("v 0 nan 0\n", "not finite");
  refuse("v 0 0\n", "three coordinates");
  refuse("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 1\n", "twice");
}
