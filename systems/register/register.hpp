#pragma once
// The registration system: from the rig's frame to the object's. Between triangulate and sketch, it reads the
// frame's pen events and the registration commands (engine/INPUT_LOG.md):
//   cmd mark N X Y Z  the pen tip rests on mark N of the object, at (X, Y, Z) in the object's frame: the pen's
//                     position is the mean of its samples over the last kRestWindowUs, which must hold still
//                     (their RMS distance from it at most kRestSpread)
//   cmd register      the rigid transform from the marks touched since the last registration (Umeyama,
//                     tracking::register_rigid); from then on every pen sample is mapped into the object's frame
// An object nobody modelled has no marks file: its marks are measured by touch.
//   cmd table         the pen rests on the table (three such touches, before the first registration)
//   cmd measure N     the pen rests on mark N, whose position is measured: in the object's frame after a
//                     registration; before the first, it waits for that registration to make the frame
//   cmd mark N        as cmd mark N X Y Z, with mark N's measured position
// The first cmd register with no mark touched but marks measured makes the object's frame from them: +z the
// table's normal toward the cameras, the origin the measured marks' centroid dropped onto the table, +x
// camera 0's x axis laid on the table. A mark measured twice, marks closer than kMarkSpacing or on one line,
// a table whose touches lie on a line, or a mark touched but never measured are rejected in words.
// Each later registration on measured marks measures them again: the marks and every round's rigid motion
// are then refined together over all the rounds (the first, which made the frame, held), so that a mark
// measured through a chain of 3-mark registrations does not carry their errors into every later round.
// A registration that cannot be made (fewer than 3 marks, collinear marks, a residual over kMaxResidual) is
// rejected in words, naming the mark that fits worst where the others fit, and keeps the marks touched; a
// later registration (the object turned) replaces the transform, and curves already drawn stay where they
// are. Before the first registration samples pass unchanged.
// A touch is not a curve: a stroke is held back until the pen leaves kTouchRadius around its first sample, and
// one that never does (the pen resting on a mark) is dropped. So is one during which a mark is touched: what
// was released of it is dropped by the sketch system on the mark command, which it is passed for that.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "engine/edit_command.hpp"
#include "engine/input_log.hpp"
#include "engine/session_dir.hpp"
#include "systems/tracking/registration.hpp"

namespace fire {

inline constexpr int64_t kRestWindowUs = 500'000;  // the pen rests at least this long on a mark
inline constexpr double kRestSpread = 0.002;       // metres: a resting pen's samples' RMS distance from their mean
inline constexpr size_t kRestSamples = 10;         // fewer in the window: the pen was not seen on the mark
inline constexpr double kMaxResidual = 0.005;      // metres: more means a mark touched in the wrong place
inline constexpr double kTouchRadius = 0.003;      // metres: a stroke that stays this close to its start is a touch
inline constexpr double kMarkSpacing = 0.01;       // metres: measured marks (and table touches) at least this far apart and off a line
inline constexpr size_t kTableTouches = 3;         // touches on the table that give the object's +z
inline constexpr int kRefineSweeps = 20;          // alternations of the rounds' motions and the marks' positions

struct MarkTouch {
  uint32_t mark = 0;
  Vec3 measured = Vec3::Zero();  // the pen at rest, rig frame
  Vec3 model = Vec3::Zero();     // the mark, object frame
};

struct MeasuredMark {
  uint32_t mark = 0;
  Vec3 p = Vec3::Zero();  // object frame; rig frame while `RegistrationState::transform` is none
  uint32_t line = 0;      // of its cmd measure
};

// A rest of the pen on a measured mark, rig frame: where it was measured, or touched for a registration.
struct MarkRest {
  uint32_t mark = 0;
  Vec3 rest = Vec3::Zero();
};

struct Registration {
  uint32_t line = 0;  // of its cmd register
  uint32_t marks = 0;
  double residual = 0;  // metres, RMS over the marks; for the frame made by measuring, the table touches' from their plane
  bool measured_frame = false;  // the frame made from the table and the marks measured, not fitted to given marks
};

struct RegistrationState {
  std::optional<tracking::RigidTransform> transform;  // rig frame -> object frame; none before the first registration
  std::vector<MarkTouch> touched;                     // since the last registration, one per mark (the latest touch)
  std::vector<std::pair<int64_t, Vec3>> recent;       // the pen's samples (instant, rig frame) of the last kRestWindowUs
  // The stroke being drawn: held back (its Down and samples, rig frame) until the pen leaves the touch radius.
  // Open, not released and nothing held: a mark was touched, and the pen's samples until it lifts are not drawn.
  bool stroke_open = false, stroke_released = false;
  std::vector<InputEvent> held;
  std::vector<Registration> done;  // every registration made, in order
  uint32_t touches_dropped = 0;
  std::vector<Vec3> table;            // the table touches (rig frame) before the first registration
  std::vector<MeasuredMark> measured;  // every mark measured, in the order measured
  // Where the frame was made from the table and measured marks: the rests on measured marks of each pose
  // registered, from the frame's own (whose motion, `frame_transform`, is held) to the latest.
  std::vector<std::vector<MarkRest>> rounds;
  std::optional<tracking::RigidTransform> frame_transform;

  const MeasuredMark* measured_mark(uint32_t mark) const;
  void save(SnapshotWriter& out) const;
  // False (and `in` failed) on a malformed record. A snapshot written before marks were measured by touch
  // ends before `table` and `measured`: they are read empty.
  bool load(SnapshotReader& in);
};

// Writes to `object_events` (cleared first) what the person did in the frame, for the sketch system: the pen's
// events, in the object's frame, and the commands other than mark and register, which it takes (a mark
// touched during a stroke part of which was released is passed on: the sketch system drops that stroke). The frame's
// events are read first, then the pen's events the triangulation system made of them (`pen_events`, empty
// without a rig). `tracked`: the pen comes from the rig (device reports); without it the pen is in the
// model's frame already, the events pass unchanged and mark and register are rejected. A rejected command is
// appended to `rejections`.
void register_system(const std::vector<InputEvent>& frame_events, const std::vector<InputEvent>& pen_events, bool tracked,
                     RegistrationState& state, std::vector<InputEvent>& object_events, std::vector<Rejection>& rejections);

// What the registrations so far amount to, one sentence each (for fire replay).
std::vector<std::string> describe_registration(const RegistrationState& state);

}  // namespace fire
