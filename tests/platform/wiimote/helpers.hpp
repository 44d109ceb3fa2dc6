#pragma once
// Shared by the driver's tests: reading a fake remote's output reports back.
#include <vector>

#include "platform/wiimote/protocol.hpp"

namespace fire::wiimote::test {

inline constexpr int64_t kMs = 1'000'000;

// Every output report with this id, in order.
inline std::vector<Bytes> writes_of(const std::vector<Bytes>& writes, uint8_t id) {
  std::vector<Bytes> out;
  for (const Bytes& w : writes)
    if (!w.empty() && w[0] == id) out.push_back(w);
  return out;
}

// Whether any output report set the rumble bit.
inline bool any_rumble(const std::vector<Bytes>& writes) {
  for (const Bytes& w : writes)
    if (w.size() >= 2 && (w[1] & kRumbleBit)) return true;
  return false;
}

}  // namespace fire::wiimote::test
