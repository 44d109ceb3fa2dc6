#pragma once
// The input log (format in engine/INPUT_LOG.md): everything that enters the engine, timestamped.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "engine/common.hpp"

namespace fire {

enum class EventKind : uint8_t { Pen, Down, Up, Command, Hid, Truth, Meta };
// Appended in order only: a session's snapshot stores the kind's number.
enum class CommandKind : uint8_t { Undo, Redo, Close, Delete, Sharp, Mark, Register, Hole, Table, Measure, MarkMeasured };
inline constexpr CommandKind kLastCommandKind = CommandKind::MarkMeasured;

// The registration system's commands that the pen's rest on a point makes: a mark (given or measured), a
// mark being measured, the table. What the pen drew since it went down was that touch, not a stroke.
inline bool is_touch_command(CommandKind c) {
  return c == CommandKind::Mark || c == CommandKind::MarkMeasured || c == CommandKind::Measure || c == CommandKind::Table;
}

struct InputEvent {
  int64_t t_us = 0;
  EventKind kind = EventKind::Pen;
  Vec3 p = Vec3::Zero();              // Pen sample; Delete, Sharp and Hole commands' pick point; Mark: the mark in the object's frame
  double snap = 0;                    // Pen: snap radius for a stroke end at this sample; 0: the session's setting
  CommandKind command = CommandKind::Undo;
  uint32_t mark = 0;                  // Mark, MarkMeasured and Measure commands: the mark's number
  int device = 0;                     // Hid
  bool hid_ok = true;                 // Hid: false when the hex was garbled (bytes then empty)
  std::vector<uint8_t> bytes;         // Hid: the report, report id first
  std::string name;                   // Truth name, Meta key
  std::vector<double> values;         // Truth numbers
  std::string text;                   // Meta value
  uint32_t line = 0;                  // 1-based line in the file it came from (0 if built in memory)
};

struct InputLog {
  std::vector<InputEvent> events;
  // Events dropped from the front of `events` once delivered and on disk (a live session's log, which
  // would otherwise grow with the drawing): events[0] is the log's event number `forgotten`.
  uint64_t forgotten = 0;
  size_t rejected_hid_lines = 0;      // garbled hid payloads, kept as events with hid_ok = false
  size_t hid_back_in_time = 0;        // hid lines stamped before the line above them, kept
  // The format version the log was written in (engine/INPUT_LOG.md): older logs replay by the sketch rules
  // they were drawn with (SketchSettings::topology_strokes and middle_picks_face).
  uint32_t version = 3;
};

inline constexpr uint32_t kInputLogVersion = 3;
inline constexpr std::string_view kInputLogHeader = "FIRE-LOG 3";
// The header line of a log of `version` (1 to 3), without its end of line.
inline std::string input_log_header(uint32_t version) { return "FIRE-LOG " + std::to_string(version); }

// Parses a whole log held in memory; `source` names it in error messages.
Result<InputLog> parse_input_log(std::string_view text, const std::string& source);
// Reads and parses a file; errors name the file, the line and the problem.
Result<InputLog> read_input_log(const std::string& path);

// One line of the format, ending in '\n'.
std::string format_event(const InputEvent& e);
// The header line followed by every event. A log read from a version-1 file is written as version 1, so it
// keeps replaying by its own rules.
std::string format_input_log(const std::vector<InputEvent>& events, uint32_t version = kInputLogVersion);

// Shortest text that reads back as the same double.
std::string format_double(double v);

}  // namespace fire
