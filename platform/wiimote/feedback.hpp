#pragma once
// What the remotes tell the person drawing. The player LEDs number the remotes by role (camera 0
// is player 1, camera 1 player 2, the command pad player 3). A camera that has lost the pen
// lights its fourth LED too: while the other camera still sees the pen, or after both lost it
// while it was down (one after the other within the loss delay counts as both at once, since the
// two cameras report at different instants). Each such loss gives the hand-held command pad a short rumble pulse; the
// cameras never rumble, since a camera that moves spoils the calibration. The pen is down while
// both cameras see it, the rule the tracker uses (systems/tracking/track.hpp).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "platform/wiimote/remote_machine.hpp"

namespace fire::wiimote {

struct FeedbackOptions {
  int64_t lost_after_ns = 60'000'000;   // a camera without the pen this long has lost it
  int64_t rumble_ns = 150'000'000;      // length of the pad's pulse
};

inline constexpr uint8_t kLostLed = player_led(4);

uint8_t role_leds(Role role);

class PenFeedback {
 public:
  explicit PenFeedback(FeedbackOptions options = {}) : options_(options) {}

  // A camera's IR report: whether it shows an object.
  void camera_report(int camera, bool sees_object, int64_t now);
  // A camera stopped reporting (switched off, out of range) or started again.
  void camera_available(int camera, bool available, int64_t now);
  void tick(int64_t now);

  uint8_t leds(Role role) const;
  bool rumble(int64_t now) const { return now < rumble_until_; }
  bool pen_down() const { return pen_down_; }
  int pulses() const { return pulses_; }
  // Why each pulse was given, oldest first; the caller takes them.
  std::vector<std::string> take_events();

 private:
  void update(int64_t now);

  FeedbackOptions options_;
  std::array<bool, 2> available_{true, true};
  std::array<int64_t, 2> last_seen_{INT64_MIN, INT64_MIN};
  std::array<bool, 2> sees_{};
  bool pen_down_ = false;
  bool lost_while_down_ = false;
  int64_t last_down_ = INT64_MIN;  // the last update that found the pen down
  int64_t rumble_until_ = INT64_MIN;
  int pulses_ = 0;
  std::vector<std::string> events_;
};

}  // namespace fire::wiimote
