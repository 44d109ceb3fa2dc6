#include "tools/app/app_script.hpp"

#include <sstream>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "platform/files.hpp"

namespace fire::app {
namespace {

Result<int> parse_key(const std::string& name) {
  if (name.size() == 1 && name[0] >= 'a' && name[0] <= 'z') return GLFW_KEY_A + (name[0] - 'a');
  if (name.size() == 1 && name[0] >= '0' && name[0] <= '9') return GLFW_KEY_0 + (name[0] - '0');
  if (name == "delete") return GLFW_KEY_DELETE;
  if (name == "escape") return GLFW_KEY_ESCAPE;
  if (name == "f1") return GLFW_KEY_F1;
  return Result<int>::failure("unknown key '" + name + "' (a-z, 0-9, delete, escape, f1)");
}

}  // namespace

Result<std::vector<ScriptEvent>> read_script(const std::string& path) {
  using R = Result<std::vector<ScriptEvent>>;
  auto text = read_text_file(path);
  if (!text) return R::failure(text.error());
  std::vector<ScriptEvent> events;
  std::istringstream lines(*text);
  std::string line;
  for (uint32_t number = 1; std::getline(lines, line); ++number) {
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream in(line);
    ScriptEvent s;
    std::string kind;
    if (!(in >> s.frame)) {
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      return R::failure(path + ":" + std::to_string(number) + ": expected a frame number");
    }
    auto bad = [&](const std::string& why) { return R::failure(path + ":" + std::to_string(number) + ": " + why); };
    if (!events.empty() && s.frame < events.back().frame) return bad("frames must not decrease");
    if (!(in >> kind)) return bad("expected an event after the frame");
    window::WindowEvent& e = s.event;
    if (kind == "move") {
      e.kind = window::WindowEventKind::CursorMove;
      if (!(in >> e.x >> e.y)) return bad("move needs X Y");
    } else if (kind == "press" || kind == "release") {
      e.kind = kind == "press" ? window::WindowEventKind::ButtonPress : window::WindowEventKind::ButtonRelease;
      std::string b;
      in >> b;
      if (b == "left") e.button = window::Button::Left;
      else if (b == "right") e.button = window::Button::Right;
      else if (b == "middle") e.button = window::Button::Middle;
      else return bad(kind + " needs left, right or middle");
    } else if (kind == "scroll") {
      e.kind = window::WindowEventKind::Scroll;
      if (!(in >> e.y)) return bad("scroll needs DY");
    } else if (kind == "key") {
      e.kind = window::WindowEventKind::KeyPress;
      std::string name;
      in >> name;
      for (const auto& [prefix, flag] : {std::pair{"ctrl+", window::kCtrl}, std::pair{"shift+", window::kShift}})
        while (name.rfind(prefix, 0) == 0) {
          e.mods |= flag;
          name = name.substr(std::string(prefix).size());
        }
      auto key = parse_key(name);
      if (!key) return bad(key.error());
      e.key = *key;
    } else if (kind == "resize") {
      if (!(in >> s.resize_width >> s.resize_height) || s.resize_width < 64 || s.resize_height < 64)
        return bad("resize needs WIDTH HEIGHT, at least 64 each");
    } else if (kind == "close") {
      e.kind = window::WindowEventKind::Close;
    } else {
      return bad("unknown event '" + kind + "' (move, press, release, scroll, key, resize, close)");
    }
    std::string extra;
    if (in >> extra) return bad("unexpected '" + extra + "'");
    events.push_back(s);
  }
  return events;
}

size_t deliver_script(const std::vector<ScriptEvent>& script, size_t next, uint64_t frame, window::Window& window) {
  for (; next < script.size() && script[next].frame <= frame; ++next) {
    const ScriptEvent& s = script[next];
    if (s.resize_width) window.request_size(s.resize_width, s.resize_height);
    else window.inject(s.event);
  }
  return next;
}

}  // namespace fire::app
