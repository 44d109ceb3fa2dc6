#pragma once
// Change tracking for many consumers (design card, "The live frame").
//
// Every pool element records the frame of its last write (its stamp). A consumer (refine, the snapping
// index, the renderer's uploads, the session journal) remembers the last frame it has seen and asks
// which elements carry a later stamp; nobody clears anything for the others. Besides the stamps, each
// column keeps the range of slots written during the current frame, for consumers that run every frame
// and want one contiguous upload.
#include <algorithm>
#include <cstdint>
#include <vector>

namespace fire {

using Frame = uint64_t;

// A half-open slot range [begin, end); empty when begin == end.
struct ChangedRange {
  uint32_t begin = 0;
  uint32_t end = 0;
  bool empty() const { return begin >= end; }
  uint32_t size() const { return empty() ? 0 : end - begin; }
  void add(uint32_t i) { add(i, i + 1); }
  void add(uint32_t b, uint32_t e) {
    if (b >= e) return;
    if (empty()) {
      begin = b;
      end = e;
    } else {
      begin = std::min(begin, b);
      end = std::max(end, e);
    }
  }
  friend bool operator==(const ChangedRange&, const ChangedRange&) = default;
};

// The stamps of one pool plus the range of slots written in `frame`.
struct ChangeStamps {
  std::vector<Frame> stamp;  // per slot: frame of the last write; never shrinks except at compaction
  Frame frame = 0;           // the frame `range` belongs to
  ChangedRange range;        // slots written during `frame`

  void touch(uint32_t slot, Frame now) {
    if (stamp.size() <= slot) stamp.resize(slot + 1, now);
    stamp[slot] = now;
    note(slot, slot + 1, now);
  }
  // Records that slots [b, e) were written at `now` (ranges only, for columns without per-slot stamps).
  void note(uint32_t b, uint32_t e, Frame now) {
    if (frame != now) {
      frame = now;
      range = {};
    }
    range.add(b, e);
  }
  bool changed_since(uint32_t slot, Frame seen) const { return slot >= stamp.size() || stamp[slot] > seen; }
  // Slots written after `seen`, in increasing order.
  std::vector<uint32_t> since(Frame seen) const {
    std::vector<uint32_t> out;
    for (uint32_t i = 0; i < stamp.size(); ++i)
      if (stamp[i] > seen) out.push_back(i);
    return out;
  }
  // What was written during `now` (empty when nothing was).
  ChangedRange written_in(Frame now) const { return frame == now ? range : ChangedRange{}; }
};

}  // namespace fire
