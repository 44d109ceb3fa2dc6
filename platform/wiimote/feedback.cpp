#include "platform/wiimote/feedback.hpp"

namespace fire::wiimote {

uint8_t role_leds(Role role) {
  switch (role) {
    case Role::Camera0: return player_led(1);
    case Role::Camera1: return player_led(2);
    case Role::CommandPad: return player_led(3);
  }
  return 0;
}

void PenFeedback::camera_report(int camera, bool sees_object, int64_t now) {
  if (camera < 0 || camera > 1) return;
  if (sees_object) last_seen_[camera] = now;
  update(now);
}

void PenFeedback::camera_available(int camera, bool available, int64_t now) {
  if (camera < 0 || camera > 1) return;
  available_[camera] = available;
  if (!available) last_seen_[camera] = INT64_MIN;
  update(now);
}

void PenFeedback::tick(int64_t now) { update(now); }

void PenFeedback::update(int64_t now) {
  std::array<bool, 2> sees{};
  for (int c = 0; c < 2; ++c)
    sees[c] = available_[c] && last_seen_[c] != INT64_MIN && now - last_seen_[c] < options_.lost_after_ns;
  bool pulse = false;
  for (int c = 0; c < 2; ++c) {
    if (sees_[c] && !sees[c] && sees[1 - c]) {
      pulse = true;
      events_.push_back("the pen left camera " + std::to_string(c) + "'s view" +
                        (available_[c] ? std::string() : " (the camera is gone)"));
    }
  }
  const bool down = sees[0] && sees[1];
  if (down) last_down_ = now;
  if (!sees[0] && !sees[1] && !lost_while_down_ && last_down_ != INT64_MIN &&
      now - last_down_ <= options_.lost_after_ns) {
    pulse = true;
    lost_while_down_ = true;
    events_.push_back("both cameras lost the pen while it was down");
  }
  if (sees[0] || sees[1]) lost_while_down_ = false;
  if (pulse) {
    ++pulses_;
    rumble_until_ = now + options_.rumble_ns;
  }
  sees_ = sees;
  pen_down_ = down;
}

uint8_t PenFeedback::leds(Role role) const {
  uint8_t leds = role_leds(role);
  if (is_camera(role)) {
    const int c = log_device(role);
    if (!sees_[c] && (sees_[1 - c] || lost_while_down_)) leds |= kLostLed;
  }
  return leds;
}

std::vector<std::string> PenFeedback::take_events() {
  std::vector<std::string> out;
  out.swap(events_);
  return out;
}

}  // namespace fire::wiimote
