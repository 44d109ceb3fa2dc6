#include "platform/wiimote/remote_machine.hpp"

#include <algorithm>
#include <cstdio>

namespace fire::wiimote {
namespace {

std::string hex_id(uint8_t id) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", id);
  return buf;
}

constexpr std::string_view kDriverHint =
    "is the kernel's hid-wiimote driver bound to it? FIRE needs hid-generic, which takes a Wii Remote only with "
    "hid.ignore_special_drivers=1 (`fire devices` checks; docs/wiimote.md)";

bool is_camera_register_write(const Bytes& report) {
  return report.size() > 2 && report[0] == kOutWriteMemory && report[2] == (kRegIrControl >> 16);
}

}  // namespace

std::string_view role_name(Role role) {
  switch (role) {
    case Role::Camera0: return "camera0";
    case Role::Camera1: return "camera1";
    case Role::CommandPad: return "pad";
  }
  return "?";
}

std::optional<Role> parse_role(std::string_view name) {
  if (name == "camera0") return Role::Camera0;
  if (name == "camera1") return Role::Camera1;
  if (name == "pad") return Role::CommandPad;
  return std::nullopt;
}

int log_device(Role role) { return static_cast<int>(role); }

std::string_view state_name(MachineState state) {
  switch (state) {
    case MachineState::Starting: return "starting";
    case MachineState::Running: return "running";
    case MachineState::Failed: return "failed";
  }
  return "?";
}

RemoteMachine::RemoteMachine(Role role, StartupOptions options) : role_(role), options_(options) {}

std::vector<RemoteMachine::Step> RemoteMachine::camera_steps() const {
  const uint8_t enable[] = {kIrControlEnable};
  const uint8_t mode[] = {kIrModeExtended};
  const SensitivityBlocks s = sensitivity_blocks(options_.sensitivity);
  return {{ir_pixel_clock_report(true), Await::Ack},
          {ir_logic_report(true), Await::Ack},
          {write_register_report(kRegIrControl, enable), Await::Ack},
          {write_register_report(kRegIrBlock1, s.block1), Await::Ack},
          {write_register_report(kRegIrBlock2, s.block2), Await::Ack},
          {write_register_report(kRegIrMode, mode), Await::Ack},
          {write_register_report(kRegIrControl, enable), Await::Ack, true}};
}

void RemoteMachine::plan_sequence() {
  plan_.clear();
  // The status report first: it gives the battery, and the reporting mode, sent last, survives it.
  plan_.push_back({status_request_report(), Await::Status});
  plan_.push_back({leds_report(leds_, true), Await::Ack});
  if (is_camera(role_))
    for (Step& step : camera_steps()) plan_.push_back(std::move(step));
  // The command pad reports its buttons when they change; the cameras report continuously.
  plan_.push_back({reporting_mode_report(expected_mode(), is_camera(role_), true), Await::Ack});
  next_ = 0;
  in_flight_ = false;
  resend_at_.reset();
  tries_ = 0;
  camera_refusals_ = 0;
  camera_ready_ = false;
}

void RemoteMachine::begin(int64_t now, uint8_t leds, std::vector<Bytes>& out) {
  leds_ = leds;
  state_ = MachineState::Starting;
  ++sequences_;
  seen_object_ = false;
  error_.clear();
  warning_.clear();
  last_report_ = now;
  plan_sequence();
  send_current(now, out);
}

void RemoteMachine::send_current(int64_t now, std::vector<Bytes>& out) {
  if (next_ >= plan_.size()) {
    in_flight_ = false;
    return;
  }
  out.push_back(plan_[next_].report);
  in_flight_ = true;
  sent_at_ = now;
  resend_at_.reset();
  ++tries_;
  if (plan_[next_].await == Await::Ack) {
    owed_.push_back({.report_id = plan_[next_].report[0], .sent_at = now, .token = ++last_token_});
    in_flight_token_ = last_token_;
  }
}

void RemoteMachine::forget_expired_acks(int64_t now) {
  std::erase_if(owed_, [&](const Owed& o) { return now - o.sent_at >= options_.ack_timeout_ns; });
}

void RemoteMachine::step_done(int64_t now, std::vector<Bytes>& out) {
  if (plan_[next_].camera_done) {
    camera_ready_ = true;
    if (state_ == MachineState::Running) warning_.clear();  // set up again after it was switched off
  }
  ++next_;
  tries_ = 0;
  in_flight_ = false;
  if (next_ < plan_.size()) {
    send_current(now, out);
    return;
  }
  plan_.clear();
  next_ = 0;
  if (state_ == MachineState::Starting) {
    state_ = MachineState::Running;
    failed_sequences_ = 0;
    warning_.clear();  // what made it start again is behind it
    running_since_ = now;
    last_report_ = now;
    last_status_request_ = now;
  }
}

void RemoteMachine::abandon(int64_t now, const std::string& why, std::vector<Bytes>& out) {
  ++failed_sequences_;
  if (failed_sequences_ < options_.max_sequences) {
    begin(now, leds_, out);
    warning_ = why + "; starting again";
    return;
  }
  state_ = MachineState::Failed;
  plan_.clear();
  next_ = 0;
  in_flight_ = false;
  resend_at_.reset();
  error_ = why + ", in " + std::to_string(failed_sequences_) + " start-ups: the remote does not answer; " +
           std::string(kDriverHint);
}

void RemoteMachine::restart(int64_t now, std::string why, std::vector<Bytes>& out) {
  ++restarts_;
  begin(now, leds_, out);
  warning_ = std::move(why);
}

bool RemoteMachine::mode_step_pending() const {
  for (size_t k = next_; k < plan_.size(); ++k)
    if (plan_[k].report[0] == kOutReportingMode && !(k == next_ && in_flight_)) return true;
  return false;
}

void RemoteMachine::queue_mode_step(int64_t now, std::vector<Bytes>& out) {
  const bool idle = next_ >= plan_.size();
  if (idle) {
    plan_.clear();
    next_ = 0;
  }
  plan_.push_back({reporting_mode_report(expected_mode(), is_camera(role_), true), Await::Ack});
  if (idle) send_current(now, out);
}

void RemoteMachine::queue_camera_setup(int64_t now, std::vector<Bytes>& out) {
  const bool idle = next_ >= plan_.size();
  if (idle) {
    plan_.clear();
    next_ = 0;
  }
  camera_refusals_ = 0;
  for (Step& step : camera_steps()) plan_.push_back(std::move(step));
  plan_.push_back({reporting_mode_report(expected_mode(), true, true), Await::Ack});
  if (idle) send_current(now, out);
}

bool RemoteMachine::restart_camera_steps() {
  for (size_t k = next_ + 1; k-- > 0;) {
    if (plan_[k].report[0] != kOutIrPixelClock) continue;
    next_ = k;
    tries_ = 0;
    return true;
  }
  return false;
}

void RemoteMachine::on_ack(const Ack& ack, int64_t now, std::vector<Bytes>& out) {
  forget_expired_acks(now);
  // In order: the oldest write of this id still owed an ack is the one acknowledged, and any
  // older write owed one will not get it now.
  const auto it = std::find_if(owed_.begin(), owed_.end(), [&](const Owed& o) { return o.report_id == ack.report_id; });
  if (it == owed_.end()) return;  // unasked for, or later than its write's timeout
  const uint64_t token = it->token;
  owed_.erase(owed_.begin(), it + 1);
  // A late acknowledgement of a write sent before the one in flight.
  if (!in_flight_ || token != in_flight_token_) return;
  if (ack.error == 0) {
    step_done(now, out);
    return;
  }
  const std::string refused = "report " + hex_id(ack.report_id) + " refused with error " + std::to_string(ack.error);
  if (ack.error == kAckNoCamera && is_camera_register_write(plan_[next_].report)) {
    // The camera did not answer: it is off, so its set-up starts again from the pixel clock.
    if (++camera_refusals_ >= options_.max_tries) {
      abandon(now, refused + " (the camera is off) in " + std::to_string(camera_refusals_) + " camera set-ups", out);
      return;
    }
    if (restart_camera_steps()) {
      ++resends_;
      send_current(now, out);
      return;
    }
  }
  if (tries_ >= options_.max_tries) {
    abandon(now, refused, out);
    return;
  }
  ++resends_;
  if (ack.error == kAckBusy) {
    in_flight_ = false;
    resend_at_ = now + options_.busy_wait_ns;
    return;
  }
  send_current(now, out);
}

void RemoteMachine::on_report(std::span<const uint8_t> report, int64_t now, std::vector<Bytes>& out) {
  if (report.empty()) return;
  last_report_ = now;
  if (const auto status = parse_status(report)) {
    status_ = *status;
    if (state_ == MachineState::Failed) return;
    if (in_flight_ && plan_[next_].await == Await::Status) {
      step_done(now, out);
    } else if (is_camera(role_) && camera_ready_ && !status->camera_on()) {
      // An extension event, or another driver, switched the camera off; Dolphin sets it up again.
      camera_ready_ = false;
      warning_ = "the camera was switched off (status report): setting it up again";
      queue_camera_setup(now, out);
    } else if (!mode_step_pending()) {
      // After any status report the remote stops reporting until it is sent its mode again.
      queue_mode_step(now, out);
    }
    return;
  }
  if (state_ == MachineState::Failed) return;
  if (const auto ack = parse_ack(report)) {
    on_ack(*ack, now, out);
    return;
  }
  if (state_ != MachineState::Running || !is_data_report(report[0])) return;
  if (report[0] != expected_mode()) {
    if (now - running_since_ < options_.mode_grace_ns || next_ < plan_.size()) return;
    const std::string why = "reports in mode " + hex_id(report[0]) + " instead of " + hex_id(expected_mode());
    if (mode_restarts_ < options_.max_mode_restarts) {
      ++mode_restarts_;
      restart(now, why + ": setting the remote up again", out);
    } else {
      state_ = MachineState::Failed;
      plan_.clear();
      next_ = 0;
      in_flight_ = false;
      error_ = why + " after " + std::to_string(mode_restarts_) + " restarts: another driver changes its mode; " +
               std::string(kDriverHint);
    }
    return;
  }
  if (ir_blob_count(report).value_or(0) > 0) {
    if (!seen_object_ && dark_restarts_ >= options_.max_dark_restarts) warning_.clear();
    seen_object_ = true;
  }
}

void RemoteMachine::tick(int64_t now, std::vector<Bytes>& out) {
  if (state_ == MachineState::Failed) return;
  if (resend_at_) {
    if (now >= *resend_at_) send_current(now, out);
    return;
  }
  if (in_flight_) {
    if (now - sent_at_ < options_.ack_timeout_ns) return;
    forget_expired_acks(now);
    if (tries_ >= options_.max_tries) {
      const Step& step = plan_[next_];
      abandon(now,
              step.await == Await::Status
                  ? "no status report after " + std::to_string(tries_) + " requests"
                  : "no acknowledgement of report " + hex_id(step.report[0]) + " after " + std::to_string(tries_) + " tries",
              out);
    } else {
      ++resends_;
      send_current(now, out);
    }
    return;
  }
  if (state_ != MachineState::Running) return;
  if (is_camera(role_)) {
    if (!seen_object_ && now - running_since_ >= options_.dark_after_ns) {
      if (dark_restarts_ < options_.max_dark_restarts) {
        ++dark_restarts_;
        restart(now, "the camera shows no IR object: setting it up again", out);
        return;
      }
      if (warning_.empty())
        warning_ = "the camera shows no IR object: is the pen on, and in its view? (docs/wiimote.md)";
    }
    if (now - last_report_ >= options_.stall_after_ns) {
      warning_ = "no reports: asking for them again; " + std::string(kDriverHint);
      last_report_ = now;
      queue_mode_step(now, out);
      return;
    }
  }
  if (now - last_status_request_ >= options_.battery_every_ns) {
    last_status_request_ = now;
    out.push_back(status_request_report());
  }
}

}  // namespace fire::wiimote
