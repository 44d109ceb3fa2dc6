#pragma once
// One remote's start-up and upkeep as a state machine, free of threads, devices and clocks: it is
// fed the reports that arrive and the time, and answers with the output reports to write. The
// sequence is the notes' IR camera initialisation (shared/wiimote-protocol.md). Every report
// whose acknowledgement it waits for asks for one (bit 0x02); it never waits for one it did not
// ask for; each wait has a timeout and a bounded number of tries, and a sequence that cannot
// finish is restarted a bounded number of times before the remote is given up with a reason.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "platform/wiimote/protocol.hpp"

namespace fire::wiimote {

enum class Role : uint8_t { Camera0, Camera1, CommandPad };
// "camera0", "camera1", "pad": the names the rig file and the input log use.
std::string_view role_name(Role role);
std::optional<Role> parse_role(std::string_view name);
// The `hid <device>` number of a remote in the input log: 0 and 1 are the cameras (left, right).
int log_device(Role role);
inline bool is_camera(Role role) { return role != Role::CommandPad; }

struct StartupOptions {
  int sensitivity = 3;  // 1..5, or kHighSensitivity
  int64_t ack_timeout_ns = 200'000'000;
  int max_tries = 4;       // sends of one report before its sequence is abandoned
  int max_sequences = 3;   // sequences abandoned before the remote is given up
  // A camera that shows no IR object this long after starting may have come up dark: it is set up
  // again, a bounded number of times, then runs on with a warning (the pen may simply be off).
  int64_t dark_after_ns = 3'000'000'000;
  int max_dark_restarts = 2;
  // Reports in the old mode may still be on their way after the new mode was acknowledged.
  int64_t mode_grace_ns = 100'000'000;
  int max_mode_restarts = 3;  // a remote that keeps switching modes has another driver beside FIRE
  int64_t stall_after_ns = 1'000'000'000;  // a camera silent this long is asked for its mode again
  int64_t battery_every_ns = 60'000'000'000;
};

enum class MachineState : uint8_t { Starting, Running, Failed };
std::string_view state_name(MachineState state);

class RemoteMachine {
 public:
  RemoteMachine(Role role, StartupOptions options);

  // (Re)starts the whole sequence. `leds` are the LEDs the sequence sets.
  void begin(int64_t now, uint8_t leds, std::vector<Bytes>& out);
  // A report from the remote, whatever it holds.
  void on_report(std::span<const uint8_t> report, int64_t now, std::vector<Bytes>& out);
  // Timeouts and periodic work.
  void tick(int64_t now, std::vector<Bytes>& out);
  // The LEDs a later restart should set.
  void set_leds(uint8_t leds) { leds_ = leds; }

  Role role() const { return role_; }
  MachineState state() const { return state_; }
  const std::string& error() const { return error_; }      // Failed: why, and what to do
  const std::string& warning() const { return warning_; }  // Running, but something is off
  std::optional<StatusReport> status() const { return status_; }  // the last status report
  int sequences() const { return sequences_; }   // sequences begun, restarts included
  int resends() const { return resends_; }       // reports sent again after a timeout or an error ack
  int restarts() const { return restarts_; }     // sequences restarted because the camera came up wrong
  uint8_t expected_mode() const { return is_camera(role_) ? kInIrExtended : kInButtons; }

 private:
  enum class Await : uint8_t { Ack, Status };
  struct Step {
    Bytes report;
    Await await = Await::Ack;
  };
  void plan_sequence();
  void send_current(int64_t now, std::vector<Bytes>& out);
  void step_done(int64_t now, std::vector<Bytes>& out);
  void abandon(int64_t now, const std::string& why, std::vector<Bytes>& out);
  void restart(int64_t now, std::string why, std::vector<Bytes>& out);
  bool mode_step_pending() const;
  void queue_mode_step(int64_t now, std::vector<Bytes>& out);

  Role role_;
  StartupOptions options_;
  MachineState state_ = MachineState::Starting;
  uint8_t leds_ = 0;
  std::vector<Step> plan_;
  size_t next_ = 0;         // the step in flight (or to send), plan_.size() when idle
  bool in_flight_ = false;
  int64_t sent_at_ = 0;
  int tries_ = 0;
  int sequences_ = 0;
  int failed_sequences_ = 0;
  int resends_ = 0;
  int restarts_ = 0;
  int dark_restarts_ = 0;
  int mode_restarts_ = 0;
  int64_t running_since_ = 0;
  int64_t last_report_ = 0;
  int64_t last_status_request_ = 0;
  bool seen_object_ = false;
  std::optional<StatusReport> status_;
  std::string error_, warning_;
};

}  // namespace fire::wiimote
