#pragma once
// What each camera of a simulated rig saw, for a fake remote to show: the blobs of the simulator's
// camera reports in arrival order, held until the next one.
#include <algorithm>
#include <array>
#include <iterator>
#include <utility>
#include <vector>

#include "engine/input_log.hpp"
#include "platform/wiimote/protocol.hpp"
#include "systems/tracking/hid.hpp"

namespace fire::wiimote::test {

struct SimulatedBlobs {
  std::array<std::vector<std::pair<int64_t, IrObjects>>, 2> frames;  // (arrival ns, blobs) per camera
  // What camera `camera` shows `t_ns` after the simulation began: the last report that had arrived.
  IrObjects at(int camera, int64_t t_ns) const {
    const auto& f = frames[camera];
    auto it = std::upper_bound(f.begin(), f.end(), t_ns,
                               [](int64_t t, const std::pair<int64_t, IrObjects>& p) { return t < p.first; });
    return it == f.begin() ? IrObjects{} : std::prev(it)->second;
  }
};

// The blobs of a simulated session's camera reports (devices 0 and 1, mode 0x33).
inline SimulatedBlobs simulated_blobs_of(const std::vector<InputEvent>& events) {
  SimulatedBlobs out;
  for (const InputEvent& e : events) {
    if (e.kind != EventKind::Hid || e.device < 0 || e.device > 1) continue;
    const tracking::DecodedReport d = tracking::decode_ir_report(e.bytes);
    if (d.status != tracking::ReportStatus::Ok) continue;
    IrObjects o{};
    for (int k = 0; k < 4; ++k) {
      const tracking::IrSlot& s = d.report.slots[k];
      o[k] = {.seen = s.seen, .x = s.x, .y = s.y, .size = s.size};
    }
    out.frames[e.device].push_back({e.t_us * 1000, o});
  }
  return out;
}

}  // namespace fire::wiimote::test
