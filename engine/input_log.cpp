#include "engine/input_log.hpp"

#include "engine/text.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

namespace fire {

std::string format_double(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

namespace {

bool parse_double(std::string_view s, double& out) {
  auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

bool parse_int64(std::string_view s, int64_t& out) {
  auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool parse_hex(std::string_view s, std::vector<uint8_t>& out) {
  if (s.size() % 2 != 0) return false;
  out.clear();
  for (size_t i = 0; i < s.size(); i += 2) {
    int hi = hex_digit(s[i]), lo = hex_digit(s[i + 1]);
    if (hi < 0 || lo < 0) return false;
    out.push_back(static_cast<uint8_t>(hi * 16 + lo));
  }
  return true;
}

bool parse_point(const std::vector<std::string_view>& f, size_t first, Vec3& p) {
  if (f.size() != first + 3) return false;
  for (int k = 0; k < 3; ++k)
    if (!parse_double(f[first + k], p[k])) return false;
  return true;
}

}  // namespace

Result<InputLog> parse_input_log(std::string_view text, const std::string& source) {
  auto fail = [&](uint32_t line, const std::string& why) {
    return Result<InputLog>::failure(source + ":" + std::to_string(line) + ": " + why);
  };
  if (text.empty()) return Result<InputLog>::failure(source + ": empty input log (expected the header '" + std::string(kInputLogHeader) + "')");
  InputLog log;
  size_t pos = 0;
  uint32_t line_no = 0;
  int64_t last_t = INT64_MIN;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    ++line_no;
    if (end == std::string_view::npos)
      return fail(line_no, "truncated input log: the last line has no end of line (was the writer cut off?)");
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    if (line_no == 1) {
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      if (line.substr(0, 9) == "FIRE-LOG ") {
        if (line == "FIRE-LOG 1") log.version = 1;
        else if (line == "FIRE-LOG 2") log.version = 2;
        else if (line != kInputLogHeader)
          return fail(1, "unknown input log version '" + std::string(line.substr(9)) + "' (this build reads versions 1 to 3)");
        continue;
      }
      return fail(1, "not a FIRE input log (the first line must be '" + std::string(kInputLogHeader) + "')");
    }
    auto f = split_fields(line);
    if (f.empty() || f[0][0] == '#') continue;
    InputEvent e;
    e.line = line_no;
    if (f.size() < 2) return fail(line_no, "expected '<t_us> <kind> ...'");
    if (!parse_int64(f[0], e.t_us)) return fail(line_no, "bad timestamp '" + std::string(f[0]) + "'");
    std::string_view kind = f[1];
    // A device report stamped before the line above it is the device's problem, not the file's: kept and
    // counted, for the triangulation system to drop. Any other line must keep the log's time order.
    if (e.t_us < last_t && kind == "hid") {
      ++log.hid_back_in_time;
    } else if (e.t_us < last_t) {
      return fail(line_no, "timestamp goes back in time (" + std::to_string(e.t_us) + " after " + std::to_string(last_t) + ")");
    } else {
      last_t = e.t_us;
    }
    if (kind == "pen") {
      e.kind = EventKind::Pen;
      // An optional fourth number: the snap radius the sample was drawn with (a mouse's, from screen pixels).
      const bool with_snap = f.size() == 6;
      if (with_snap) {
        if (!parse_double(f[5], e.snap) || !(e.snap > 0) || !std::isfinite(e.snap))
          return fail(line_no, "pen's snap radius must be a positive finite number");
        f.pop_back();
      }
      if (!parse_point(f, 2, e.p)) return fail(line_no, "pen needs three numbers x y z and an optional snap radius");
    } else if (kind == "down" || kind == "up") {
      e.kind = kind == "down" ? EventKind::Down : EventKind::Up;
      if (f.size() != 2) return fail(line_no, std::string(kind) + " takes no fields");
    } else if (kind == "cmd") {
      e.kind = EventKind::Command;
      if (f.size() < 3)
        return fail(line_no, "cmd needs a command: undo, redo, close, delete x y z, sharp x y z, hole x y z, mark N [x y z], "
                              "measure N, table or register");
      std::string_view c = f[2];
      if (c == "undo" || c == "redo" || c == "close" || c == "register" || c == "table") {
        e.command = c == "undo"    ? CommandKind::Undo
                    : c == "redo"  ? CommandKind::Redo
                    : c == "close" ? CommandKind::Close
                    : c == "table" ? CommandKind::Table
                                   : CommandKind::Register;
        if (f.size() != 3) return fail(line_no, "cmd " + std::string(c) + " takes no fields");
      } else if (c == "delete" || c == "sharp" || c == "hole") {
        e.command = c == "delete" ? CommandKind::Delete : c == "sharp" ? CommandKind::Sharp : CommandKind::Hole;
        if (!parse_point(f, 3, e.p)) return fail(line_no, "cmd " + std::string(c) + " needs three numbers x y z");
      } else if (c == "mark" || c == "measure") {
        // A mark's coordinates come with it, or from its measuring (cmd measure N) earlier in the session.
        const bool measure = c == "measure", given = f.size() == 7;
        e.command = measure ? CommandKind::Measure : given ? CommandKind::Mark : CommandKind::MarkMeasured;
        int64_t mark = -1;
        const bool number = f.size() >= 4 && parse_int64(f[3], mark) && mark >= 0 && mark <= int64_t(UINT32_MAX);
        if (measure && (f.size() != 4 || !number)) return fail(line_no, "cmd measure needs the mark's number (0 or more) and nothing else");
        if (!measure && (!number || (f.size() != 4 && !given) || (given && (!parse_point(f, 4, e.p) || !is_finite(e.p)))))
          return fail(line_no, "cmd mark needs the mark's number (0 or more), then its finite object coordinates x y z unless it "
                               "was measured (cmd measure N)");
        e.mark = uint32_t(mark);
      } else {
        return fail(line_no, "unknown command '" + std::string(c) + "'");
      }
    } else if (kind == "hid") {
      e.kind = EventKind::Hid;
      int64_t device = 0;
      if (f.size() != 4 || !parse_int64(f[2], device) || device < 0 || device > 255)
        return fail(line_no, "hid needs '<device> <hex bytes>'");
      e.device = static_cast<int>(device);
      if (!parse_hex(f[3], e.bytes)) {
        e.hid_ok = false;
        e.bytes.clear();
        ++log.rejected_hid_lines;
      }
    } else if (kind == "truth") {
      e.kind = EventKind::Truth;
      if (f.size() < 3) return fail(line_no, "truth needs a name");
      e.name = std::string(f[2]);
      for (size_t k = 3; k < f.size(); ++k) {
        double v;
        if (!parse_double(f[k], v)) return fail(line_no, "truth value '" + std::string(f[k]) + "' is not a number");
        e.values.push_back(v);
      }
    } else if (kind == "meta") {
      e.kind = EventKind::Meta;
      if (f.size() < 3) return fail(line_no, "meta needs a key");
      e.name = std::string(f[2]);
      // The text starts after the key field itself; searching for the key's text could match it earlier
      // in the line (in the timestamp or the word meta).
      size_t at = static_cast<size_t>(f[2].data() - line.data()) + f[2].size();
      while (at < line.size() && line[at] == ' ') ++at;
      e.text = std::string(line.substr(at));
    } else {
      return fail(line_no, "unknown event kind '" + std::string(kind) + "'");
    }
    log.events.push_back(std::move(e));
  }
  if (line_no == 0) return Result<InputLog>::failure(source + ": empty input log");
  return log;
}

Result<InputLog> read_input_log(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Result<InputLog>::failure(path + ": cannot open input log");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_input_log(ss.str(), path);
}

std::string format_event(const InputEvent& e) {
  std::string s = std::to_string(e.t_us) + ' ';
  auto point = [&](const Vec3& p) {
    return format_double(p.x()) + ' ' + format_double(p.y()) + ' ' + format_double(p.z());
  };
  switch (e.kind) {
    case EventKind::Pen:
      s += "pen " + point(e.p);
      if (e.snap > 0) s += ' ' + format_double(e.snap);
      break;
    case EventKind::Down: s += "down"; break;
    case EventKind::Up: s += "up"; break;
    case EventKind::Command:
      switch (e.command) {
        case CommandKind::Undo: s += "cmd undo"; break;
        case CommandKind::Redo: s += "cmd redo"; break;
        case CommandKind::Close: s += "cmd close"; break;
        case CommandKind::Delete: s += "cmd delete " + point(e.p); break;
        case CommandKind::Sharp: s += "cmd sharp " + point(e.p); break;
        case CommandKind::Hole: s += "cmd hole " + point(e.p); break;
        case CommandKind::Mark: s += "cmd mark " + std::to_string(e.mark) + ' ' + point(e.p); break;
        case CommandKind::Register: s += "cmd register"; break;
        case CommandKind::Table: s += "cmd table"; break;
        case CommandKind::Measure: s += "cmd measure " + std::to_string(e.mark); break;
        case CommandKind::MarkMeasured: s += "cmd mark " + std::to_string(e.mark); break;
      }
      break;
    case EventKind::Hid: {
      static const char* digits = "0123456789abcdef";
      s += "hid " + std::to_string(e.device) + ' ';
      for (uint8_t b : e.bytes) {
        s += digits[b >> 4];
        s += digits[b & 15];
      }
      break;
    }
    case EventKind::Truth:
      s += "truth " + e.name;
      for (double v : e.values) s += ' ' + format_double(v);
      break;
    case EventKind::Meta: s += "meta " + e.name + (e.text.empty() ? "" : " " + e.text); break;
  }
  s += '\n';
  return s;
}

std::string format_input_log(const std::vector<InputEvent>& events, uint32_t version) {
  std::string s = input_log_header(version);
  s += '\n';
  for (const auto& e : events) s += format_event(e);
  return s;
}

}  // namespace fire
