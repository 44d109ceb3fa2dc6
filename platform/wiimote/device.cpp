#include "platform/wiimote/device.hpp"

#include <cctype>

#include "platform/clock.hpp"

namespace fire::wiimote {

Clock system_clock() { return [] { return monotonic_ns(); }; }

std::string normalize_address(const std::string& serial) {
  std::string hex;
  for (char c : serial) {
    if (c == ':' || c == '-') continue;
    if (!std::isxdigit(static_cast<unsigned char>(c))) return serial;
    hex += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  if (hex.size() != 12) return serial;
  std::string out;
  for (size_t i = 0; i < 12; i += 2) {
    if (i) out += ':';
    out += hex.substr(i, 2);
  }
  return out;
}

}  // namespace fire::wiimote
