#include "tools/app/pad.hpp"

#include "platform/wiimote/protocol.hpp"

namespace fire::app {

const std::array<PadBinding, 11>& pad_bindings() {
  using namespace wiimote;
  static const std::array<PadBinding, 11> bindings = {{
      {kButtonA, "A", PadAction::CloseBorder, "close the border to its first vertex"},
      {kButtonB, "B", PadAction::Undo, "undo"},
      {kButtonPlus, "+", PadAction::Redo, "redo"},
      {kButtonMinus, "-", PadAction::DeleteLastCurve, "delete the curve drawn last"},
      {kButtonOne, "1", PadAction::SharpLastCurve, "the curve drawn last sharp / smooth"},
      {kButtonTwo, "2", PadAction::TouchMark, "the pen rests on the mark shown: touched (without a marks file: measured, or touched once measured)"},
      {kButtonHome, "Home", PadAction::Register, "register the object on the marks touched (3 or more)"},
      {kButtonLeft, "left", PadAction::PreviousMark, "show the previous mark"},
      {kButtonRight, "right", PadAction::NextMark, "show the next mark"},
      {kButtonDown, "down", PadAction::HoleLastTouched, "the face the pen last touched becomes a hole (no surface)"},
      {kButtonUp, "up", PadAction::TouchTable, "the pen rests on the table: touched (3 times, to measure the marks)"},
  }};
  return bindings;
}

std::vector<std::string> pad_help_lines() {
  std::vector<std::string> lines;
  for (const PadBinding& b : pad_bindings()) {
    std::string line = "pad " + std::string(b.name);
    line.resize(16, ' ');
    lines.push_back(line + std::string(b.what));
  }
  return lines;
}

std::vector<PadAction> PadPresses::on_report(std::span<const uint8_t> report) {
  std::vector<PadAction> out;
  const std::optional<uint16_t> buttons = wiimote::core_buttons(report);
  if (!buttons) return out;
  const uint16_t pressed = held_ ? uint16_t(*buttons & ~*held_) : uint16_t{0};
  held_ = *buttons;
  for (const PadBinding& b : pad_bindings())
    if (pressed & b.button) out.push_back(b.action);
  return out;
}

std::optional<Vec3> last_curve_point(const EditHistory& history) {
  const EditCommand* drawn = history.last_drawn();
  if (!drawn) return std::nullopt;
  return drawn->points[drawn->points.size() / 2];
}

}  // namespace fire::app
