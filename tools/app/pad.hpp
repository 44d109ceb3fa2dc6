#pragma once
// The command pad (thesis 3.5, the modal-interface problem): a Wii Remote with the pad role, held in the
// hand that does not draw, whose buttons give the live app's commands, so the person never reaches for the
// keyboard while the pen is on the object. Its reports are in the input log as they came (`hid 2 ...`);
// a press becomes a logged command (`cmd ...`) when the app takes the report, so a replay needs neither.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "engine/common.hpp"
#include "systems/split/edit.hpp"

namespace fire::app {

enum class PadAction : uint8_t { CloseBorder, Undo, Redo, DeleteLastCurve, SharpLastCurve, TouchMark, Register, PreviousMark, NextMark, HoleLastTouched, TouchTable };

// Without a marks file the marks are measured by touch, and the pad shows their ids from 0 to this less one.
inline constexpr size_t kMeasuredMarkIds = 16;

struct PadBinding {
  uint16_t button = 0;  // a wiimote::kButton* bit
  std::string_view name;
  PadAction action = PadAction::Undo;
  std::string_view what;
};

// The mapping, in the order the help lists it.
const std::array<PadBinding, 11>& pad_bindings();
// One help line a binding: "pad A           close the border to its first vertex".
std::vector<std::string> pad_help_lines();

// The pad's presses, from its reports in log order: a button held in a report and not in the one before.
class PadPresses {
 public:
  // The actions of the buttons `report` shows newly pressed, in pad_bindings() order; none for a report
  // that carries no buttons (see wiimote::core_buttons).
  std::vector<PadAction> on_report(std::span<const uint8_t> report);
  // The pad went away: a button still held when it comes back is not a new press.
  void forget() { held_.reset(); }

 private:
  std::optional<uint16_t> held_;  // none before the first report: what is held then was pressed before
};

// A point on the curve drawn last (the middle of its polyline), for the pad's delete and sharp commands,
// which pick the curve nearest a point; none when nothing drawn can be undone.
std::optional<Vec3> last_curve_point(const EditHistory& history);

}  // namespace fire::app
