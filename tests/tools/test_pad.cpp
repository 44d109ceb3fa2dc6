// The command pad (tools/app/pad.hpp): presses from its reports, the mapping the help lists, the curve
// drawn last; and the fake person's presses for the simulated commands (tools/app/fake_rig.hpp).
#include <catch2/catch.hpp>

#include <set>

#include "platform/wiimote/protocol.hpp"
#include "systems/split/edit.hpp"
#include "tools/app/fake_rig.hpp"
#include "tools/app/pad.hpp"

using namespace fire;
using namespace fire::app;
using namespace fire::wiimote;

namespace {

Bytes buttons_report(uint16_t buttons) { return {kInButtons, uint8_t(buttons >> 8), uint8_t(buttons)}; }

InputEvent command_at(double t_s, CommandKind kind, uint32_t mark = 0) {
  InputEvent e;
  e.kind = EventKind::Command;
  e.t_us = int64_t(t_s * 1e6);
  e.command = kind;
  e.mark = mark;
  return e;
}

}  // namespace

TEST_CASE("pad: a press is a button held now and not in the report before") {
  PadPresses pad;
  // What is held when the pad is first heard from was pressed before: not a press.
  CHECK(pad.on_report(buttons_report(kButtonA)).empty());
  CHECK(pad.on_report(buttons_report(kButtonA)).empty());
  CHECK(pad.on_report(buttons_report(kButtonA | kButtonB)) == std::vector{PadAction::Undo});
  CHECK(pad.on_report(buttons_report(0)).empty());
  // Two at once, in the help's order.
  CHECK(pad.on_report(buttons_report(kButtonHome | kButtonA)) ==
        std::vector{PadAction::CloseBorder, PadAction::Register});
  // A report without buttons changes nothing: the next one still sees A held.
  CHECK(pad.on_report(Bytes{0x3D, 0x00, 0x00}).empty());
  CHECK(pad.on_report(Bytes{kInButtons, 0x00}).empty());  // truncated
  CHECK(pad.on_report(buttons_report(kButtonA)).empty());
  // The pad went away and came back with A still down: not a press.
  pad.forget();
  CHECK(pad.on_report(buttons_report(kButtonA)).empty());
  CHECK(pad.on_report(buttons_report(0)).empty());
  CHECK(pad.on_report(buttons_report(kButtonPlus)) == std::vector{PadAction::Redo});
}

TEST_CASE("pad: every binding has its own button and action, and a help line") {
  std::set<uint16_t> buttons;
  std::set<PadAction> actions;
  for (const PadBinding& b : pad_bindings()) {
    CHECK((b.button & kAllButtons) == b.button);
    CHECK(__builtin_popcount(b.button) == 1);
    buttons.insert(b.button);
    actions.insert(b.action);
  }
  CHECK(buttons.size() == pad_bindings().size());
  CHECK(actions.size() == pad_bindings().size());
  const std::vector<std::string> help = pad_help_lines();
  REQUIRE(help.size() == pad_bindings().size());
  CHECK(help[0] == "pad A           close the border to its first vertex");
}

TEST_CASE("pad: the curve drawn last is the newest undoable curve, not an undone one") {
  Mesh mesh;
  EditHistory history;
  CHECK_FALSE(last_curve_point(history));
  EditCommand border;
  border.kind = EditKind::StartBorder;
  border.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)};
  REQUIRE(history.apply(mesh, border).ok());
  REQUIRE(last_curve_point(history));
  CHECK(*last_curve_point(history) == Vec3(1, 0, 0));
  EditCommand next;
  next.kind = EditKind::AppendBorder;
  next.points = {Vec3(2, 0, 0), Vec3(2, 1, 0), Vec3(2, 2, 0), Vec3(2, 3, 0)};
  REQUIRE(history.apply(mesh, next).ok());
  CHECK(*last_curve_point(history) == Vec3(2, 2, 0));
  REQUIRE(history.undo(mesh).ok());
  CHECK(*last_curve_point(history) == Vec3(1, 0, 0));
  REQUIRE(history.undo(mesh).ok());
  CHECK_FALSE(last_curve_point(history));
}

TEST_CASE("fake rig: the simulated person's commands as pad presses, each mark chosen the short way round") {
  const std::vector<InputEvent> commands = {
      command_at(2.0, CommandKind::Mark, 0),  // shown at first: no choosing
      command_at(3.0, CommandKind::Mark, 4),  // shown 1: right 3 times, or left 3 times: right
      command_at(4.0, CommandKind::Mark, 3),  // shown 5: left twice
      command_at(5.0, CommandKind::Register),
      command_at(6.0, CommandKind::Undo),
  };
  const std::vector<PadPress> presses = pad_presses_for(commands, 6);
  std::vector<std::pair<double, uint16_t>> got;
  for (const PadPress& p : presses) got.push_back({double(p.t_ns) * 1e-9, p.button});
  const std::vector<std::pair<double, uint16_t>> expected = {
      {2.0, kButtonTwo},  {2.7, kButtonRight}, {2.8, kButtonRight}, {2.9, kButtonRight}, {3.0, kButtonTwo},
      {3.8, kButtonLeft}, {3.9, kButtonLeft},  {4.0, kButtonTwo},   {5.0, kButtonHome},  {6.0, kButtonB}};
  REQUIRE(got.size() == expected.size());
  for (size_t k = 0; k < got.size(); ++k) {
    INFO("press " << k);
    CHECK(got[k].first == Approx(expected[k].first));
    CHECK(got[k].second == expected[k].second);
  }
  // Presses never overlap: each is released before the next begins.
  for (size_t k = 1; k < presses.size(); ++k) CHECK(presses[k].t_ns - presses[k - 1].t_ns >= kPadHoldNs);
}
