#pragma once
// One remote's start-up and upkeep as a state machine, free of threads, devices and clocks: it is
// fed the reports that arrive and the time, and answers with the output reports to write. The
// sequence is the notes' IR camera initialisation (shared/wiimote-protocol.md). Every report
// whose acknowledgement it waits for asks for one (bit 0x02); it never waits for one it did not
// ask for. Acknowledgements are matched to writes in order, as the kernel's hid-wiimote does: every
// set-up write is report 0x16, so a late ack of one write must not pass for the next. A write is
// sent again only once its ack can no longer come (the kernel's 1 s), or after an error ack; each
// wait has a bounded number of tries, and a sequence that cannot finish is restarted a bounded
// number of times before the remote is given up with a reason.
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
  int64_t ack_timeout_ns = 1'000'000'000;  // the kernel's: an ack later than this is taken as lost
  int64_t busy_wait_ns = 50'000'000;       // after error 4 (busy), before the same report again
  int max_tries = 4;       // sends of one report (or camera set-ups refused with error 7) before its sequence is abandoned
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
    bool camera_done = false;  // the last step of the camera's set-up
  };
  // A write whose acknowledgement may still come.
  struct Owed {
    uint8_t report_id = 0;
    int64_t sent_at = 0;
    uint64_t token = 0;
  };
  void plan_sequence();
  std::vector<Step> camera_steps() const;
  void on_ack(const Ack& ack, int64_t now, std::vector<Bytes>& out);
  void forget_expired_acks(int64_t now);
  bool restart_camera_steps();
  void queue_camera_setup(int64_t now, std::vector<Bytes>& out);
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
  std::optional<int64_t> resend_at_;  // the step waits for a busy remote, not for an ack
  std::vector<Owed> owed_;            // oldest first
  uint64_t last_token_ = 0;
  uint64_t in_flight_token_ = 0;
  int tries_ = 0;
  int camera_refusals_ = 0;  // camera set-ups restarted after error 7, this sequence
  bool camera_ready_ = false;
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
