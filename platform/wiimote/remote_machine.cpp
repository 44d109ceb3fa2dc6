#include "platform/wiimote/remote_machine.hpp"

#include <cstdio>

namespace fire::wiimote {
namespace {

std::string hex_id(uint8_t id) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", id);
  return buf;
}

constexpr std::string_view kDriverHint =
    "is the kernel's hid-wiimote driver bound to it? (docs/wiimote.md says how to unbind it)";

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

void RemoteMachine::plan_sequence() {
  plan_.clear();
  // The status report first: it gives the battery, and the reporting mode, sent last, survives it.
  plan_.push_back({status_request_report(), Await::Status});
  plan_.push_back({leds_report(leds_, true), Await::Ack});
  if (is_camera(role_)) {
    const uint8_t enable[] = {kIrControlEnable};
    const uint8_t mode[] = {kIrModeExtended};
    const SensitivityBlocks s = sensitivity_blocks(options_.sensitivity);
    plan_.push_back({ir_pixel_clock_report(true), Await::Ack});
    plan_.push_back({ir_logic_report(true), Await::Ack});
    plan_.push_back({write_register_report(kRegIrControl, enable), Await::Ack});
    plan_.push_back({write_register_report(kRegIrBlock1, s.block1), Await::Ack});
    plan_.push_back({write_register_report(kRegIrBlock2, s.block2), Await::Ack});
    plan_.push_back({write_register_report(kRegIrMode, mode), Await::Ack});
    plan_.push_back({write_register_report(kRegIrControl, enable), Await::Ack});
  }
  // The command pad reports its buttons when they change; the cameras report continuously.
  plan_.push_back({reporting_mode_report(expected_mode(), is_camera(role_), true), Await::Ack});
  next_ = 0;
  in_flight_ = false;
  tries_ = 0;
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
  ++tries_;
}

void RemoteMachine::step_done(int64_t now, std::vector<Bytes>& out) {
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

void RemoteMachine::on_report(std::span<const uint8_t> report, int64_t now, std::vector<Bytes>& out) {
  if (report.empty()) return;
  last_report_ = now;
  if (const auto status = parse_status(report)) {
    status_ = *status;
    if (state_ == MachineState::Failed) return;
    if (in_flight_ && plan_[next_].await == Await::Status) {
      step_done(now, out);
    } else if (!mode_step_pending()) {
      // After any status report the remote stops reporting until it is sent its mode again.
      queue_mode_step(now, out);
    }
    return;
  }
  if (state_ == MachineState::Failed) return;
  if (const auto ack = parse_ack(report)) {
    // Acknowledgements of anything but the report in flight are stale or unasked for: ignored.
    if (!in_flight_ || plan_[next_].await != Await::Ack || plan_[next_].report[0] != ack->report_id) return;
    if (ack->error == 0) {
      step_done(now, out);
    } else if (tries_ >= options_.max_tries) {
      abandon(now, "report " + hex_id(ack->report_id) + " refused with error " + std::to_string(ack->error), out);
    } else {
      ++resends_;
      send_current(now, out);
    }
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
  if (const auto objects = ir_object_count(report); objects && *objects > 0) {
    if (!seen_object_ && dark_restarts_ >= options_.max_dark_restarts) warning_.clear();
    seen_object_ = true;
  }
}

void RemoteMachine::tick(int64_t now, std::vector<Bytes>& out) {
  if (state_ == MachineState::Failed) return;
  if (in_flight_) {
    if (now - sent_at_ < options_.ack_timeout_ns) return;
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
