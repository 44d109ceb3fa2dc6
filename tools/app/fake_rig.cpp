#include "tools/app/fake_rig.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <nlohmann/json.hpp>

#include "platform/files.hpp"
#include "platform/obj.hpp"
#include "systems/synth/network_from_mesh.hpp"
#include "engine/ir_report.hpp"
#include "tools/simulation/simulate.hpp"
#include "tools/app/pad.hpp"
#include "tools/app/session_rig.hpp"

namespace fire::app {

IrSlots SimulatedBlobs::at(int camera, int64_t t_ns) const {
  // Frames further apart than this are a gap (the pen unseen, a lost report): nothing to interpolate across.
  constexpr int64_t kMaxGapNs = 25'000'000;
  const auto& f = frames[size_t(camera)];
  auto next = std::upper_bound(f.begin(), f.end(), t_ns,
                               [](int64_t t, const std::pair<int64_t, IrSlots>& p) { return t < p.first; });
  if (next == f.begin()) return {};
  const auto& [t0, before] = *std::prev(next);
  if (next == f.end() || next->first - t0 > kMaxGapNs) return before;
  // The fake remote's frames are not the simulator's: a blob held from the simulator's last frame would be up
  // to a frame old, differently for each camera, and triangulated as if it were now.
  const double s = double(t_ns - t0) / double(next->first - t0);
  IrSlots out = before;
  for (size_t k = 0; k < out.size(); ++k) {
    const IrSlot &a = before[k], &b = next->second[k];
    if (!a.seen || !b.seen) continue;
    out[k].x = uint16_t(std::lround(a.x + s * (double(b.x) - a.x)));
    out[k].y = uint16_t(std::lround(a.y + s * (double(b.y) - a.y)));
  }
  return out;
}

SimulatedBlobs simulated_blobs_of(const std::vector<InputEvent>& events) {
  SimulatedBlobs out;
  for (const InputEvent& e : events) {
    if (e.kind != EventKind::Hid || e.device < 0 || e.device > 1) continue;
    const DecodedReport d = decode_ir_report(e.bytes);
    if (d.status != ReportStatus::Ok) continue;
    IrSlots o{};
    for (size_t k = 0; k < o.size(); ++k) {
      const IrSlot& s = d.report.slots[k];
      o[k] = {.seen = s.seen, .x = s.x, .y = s.y, .size = s.size};
    }
    out.frames[size_t(e.device)].push_back({e.t_us * 1000, o});
  }
  return out;
}

std::vector<PadPress> pad_presses_for(const std::vector<InputEvent>& commands, size_t mark_count) {
  constexpr int64_t kBetweenPressesNs = 100'000'000;
  auto button_of = [](PadAction action) {
    for (const PadBinding& b : pad_bindings())
      if (b.action == action) return b.button;
    return uint16_t{0};
  };
  std::vector<PadPress> presses;
  size_t shown = 0;
  for (const InputEvent& c : commands) {
    if (c.kind != EventKind::Command) continue;
    const int64_t t = c.t_us * 1000;
    PadAction action = PadAction::Undo;
    switch (c.command) {
      case CommandKind::Undo: action = PadAction::Undo; break;
      case CommandKind::Redo: action = PadAction::Redo; break;
      case CommandKind::Close: action = PadAction::CloseBorder; break;
      case CommandKind::Delete: action = PadAction::DeleteLastCurve; break;
      case CommandKind::Sharp: action = PadAction::SharpLastCurve; break;
      case CommandKind::Register: action = PadAction::Register; break;
      case CommandKind::Hole: action = PadAction::HoleLastTouched; break;
      case CommandKind::Table: action = PadAction::TouchTable; break;
      case CommandKind::Mark:
      case CommandKind::Measure:
      case CommandKind::MarkMeasured: {
        const size_t ids = c.command == CommandKind::Mark ? mark_count : kMeasuredMarkIds;
        if (ids == 0 || c.mark >= ids) continue;
        // The shorter way round to the mark, the presses ending just before the touch.
        const size_t forward = (c.mark + ids - shown) % ids, backward = ids - forward;
        const bool right = forward <= backward;
        const size_t steps = forward == 0 ? 0 : right ? forward : backward;
        for (size_t k = 0; k < steps; ++k)
          presses.push_back({t - int64_t(steps - k) * kBetweenPressesNs,
                             button_of(right ? PadAction::NextMark : PadAction::PreviousMark)});
        shown = (c.mark + 1) % ids;
        action = PadAction::TouchMark;
        break;
      }
    }
    presses.push_back({t, button_of(action)});
  }
  return presses;
}

Result<std::unique_ptr<FakeDrawingRig>> FakeDrawingRig::create(uint64_t seed, int max_strokes, bool measure_marks) {
  using R = Result<std::unique_ptr<FakeDrawingRig>>;
  auto pawn_path = bundled_data_file(kDefaultMesh);
  if (!pawn_path) return R::failure("--fake-rig: " + pawn_path.error());
  auto pawn = read_obj(*pawn_path);
  if (!pawn) return R::failure("--fake-rig: " + pawn.error());
  simulation::DrawingOptions options;
  options.max_strokes = max_strokes;
  options.measure_marks = measure_marks;
  auto placed = simulation::object_frame(pawn->positions, options.height_m);
  if (!placed) return R::failure("--fake-rig: " + placed.error());
  auto network = network_from_mesh({*placed, pawn->face_offsets, pawn->face_vertices, *pawn_path},
                                   UnrefineOptions{.unrefine = 2, .limit = true});
  if (!network) return R::failure("--fake-rig: " + network.error());
  simulation::RigOptions rig;
  rig.seed = rig.rig_seed = seed;
  auto surface = limit_mesh({*placed, pawn->face_offsets, pawn->face_vertices, *pawn_path}, simulation::kOccluderLevels);
  if (!surface) return R::failure("--fake-rig: " + surface.error());
  auto drawing = simulation::simulate_drawing(rig, options, surface->view(), simulation::drawing_network(*network));
  if (!drawing) return R::failure("--fake-rig: " + drawing.error());
  auto rig_json = simulation::true_rig_json(rig);
  if (!rig_json) return R::failure("--fake-rig: " + rig_json.error());

  std::unique_ptr<FakeDrawingRig> out(new FakeDrawingRig());
  nlohmann::ordered_json with_remotes = nlohmann::ordered_json::parse(*rig_json);
  const auto& addresses = FakeRig::kAddresses;
  with_remotes["remotes"] = {{{"address", addresses[0]}, {"role", "camera0"}},
                             {{"address", addresses[1]}, {"role", "camera1"}},
                             {{"address", addresses[2]}, {"role", "pad"}}};
  out->rig_json_ = with_remotes.dump(2) + "\n";
  if (!measure_marks) out->marks_json_ = marks_to_json(drawing->marks);
  out->duration_s_ = drawing->session.stats.duration_s;
  out->remotes_ = std::make_unique<FakeRig>(simulated_blobs_of(drawing->session.events), true,
                                            pad_presses_for(drawing->session.events, drawing->marks.size()));
  return out;
}

bool FakeDrawingRig::finished() const {
  const int64_t shown = remotes_->elapsed_ns();
  return shown >= 0 && double(shown) * 1e-9 > duration_s_ + 0.5;
}

FakeRig::FakeRig(SimulatedBlobs blobs, bool with_pad, std::vector<PadPress> presses)
    : blobs_(std::move(blobs)), presses_(std::move(presses)) {
  for (size_t r = 0; r < (with_pad ? 3u : 2u); ++r) {
    // The cameras report from phases apart, as two remotes switched on at different instants do.
    remotes_.push_back(bus_.add_remote({.address = kAddresses[r], .phase_ns = int64_t(3 + 4 * r) * 1'000'000}));
    if (r < 2)
      remotes_[r]->set_blob_source([this, r](int64_t t) {
        return origin_ns_ < 0 ? IrSlots{} : blobs_.at(int(r), t - origin_ns_);
      });
  }
}

void FakeRig::advance(int64_t ns, wiimote::Driver& driver, const std::function<void()>& each_ms) {
  for (int64_t done = 0; done < ns; done += 1'000'000) {
    clock_.advance(1'000'000);
    const int64_t now = clock_.now();
    if (origin_ns_ >= 0 && remotes_.size() == 3) {
      if (release_at_ >= 0 && now >= release_at_) {
        remotes_[2]->set_buttons(0);
        release_at_ = -1;
      }
      if (release_at_ < 0 && next_press_ < presses_.size() && now - origin_ns_ >= presses_[next_press_].t_ns) {
        remotes_[2]->set_buttons(presses_[next_press_++].button);
        release_at_ = now + kPadHoldNs;
      }
    }
    for (int k = 0; k < 4; ++k) driver.poll(0);  // a burst of held reports drains within the millisecond
    if (origin_ns_ < 0 && driver.cameras(wiimote::LinkState::Running) == 2) origin_ns_ = now;
    if (each_ms) each_ms();
  }
}

}  // namespace fire::app
