#pragma once
// The Wii Remote driver: finds the remotes, opens the ones that have a role, reads each on a
// thread of its own, writes every report that arrives to the session's input log (stamped on
// arrival by the one LogWriter), starts each camera (RemoteMachine), gives feedback through the
// LEDs and the pad's rumble (PenFeedback), and reopens a remote that went away when it comes
// back. Systems never see it: they read the log's events.
#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "platform/wiimote/device.hpp"
#include "platform/wiimote/feedback.hpp"
#include "platform/wiimote/log_writer.hpp"
#include "platform/wiimote/remote_machine.hpp"
#include "platform/wiimote/roles.hpp"

namespace fire::wiimote {

struct DriverOptions {
  StartupOptions startup;
  FeedbackOptions feedback;
  int read_timeout_ms = 10;                // how long a reader thread's read waits
  int64_t reopen_every_ns = 500'000'000;   // how often a missing remote is looked for
};

enum class LinkState : uint8_t { Missing, Starting, Running, Failed };
std::string_view link_state_name(LinkState state);

struct RemoteView {
  int device = 0;  // the `hid <device>` number in the log
  Role role = Role::Camera0;
  std::string address;
  uint16_t product = 0;
  LinkState state = LinkState::Missing;
  std::optional<StatusReport> status;  // the last status report (battery)
  std::string error;    // Missing or Failed: why
  std::string warning;  // Running, but something is off
};

struct Notice {
  int64_t t_ns = 0;
  int device = 0;  // kPenNotice: about the pen as the cameras see it, not one remote
  std::string address;
  std::string text;
};

inline constexpr int kPenNotice = -1;
// "remote 0 00:1F:32:..: running", or "pen: the stroke ended".
std::string describe(const Notice& notice);
// A remote's line in the live views: "camera0 00:1F:32:..: running, battery 80% LOW (why)".
std::string describe(const RemoteView& remote);

// What open_all found besides the remotes it opened.
struct Scan {
  std::vector<DeviceInfo> not_remotes;  // HID devices that are not Wii Remotes: left alone
  std::vector<DeviceInfo> unassigned;   // Wii Remotes without a role: left alone
  std::vector<std::string> open_errors; // remotes with a role that could not be opened, and why
};

class Driver {
 public:
  Driver(Backend& backend, LogWriter& log, std::vector<RemoteAssignment> assigned, DriverOptions options, Clock clock);
  ~Driver();
  Driver(const Driver&) = delete;
  Driver& operator=(const Driver&) = delete;

  // Enumerates, opens every remote that has a role and begins its start-up. An assigned role
  // whose remote is not there is looked for again while the driver runs. Once, before start().
  Result<Scan> open_all();
  // One step of every remote on the calling thread, for tests (never while threads run).
  void poll(int read_timeout_ms = 0);
  // One reader thread per remote; stop() (or destruction) joins them.
  void start();
  void stop();

  std::vector<RemoteView> remotes() const;
  // How many remotes are cameras in `state`, or, without one, present (in any state but Missing).
  int cameras(std::optional<LinkState> state = std::nullopt) const;
  std::vector<Notice> take_notices();
  bool pen_down() const;

 private:
  struct Link;
  bool step(Link& link, int read_timeout_ms);
  void reopen(Link& link, int64_t now);
  void lose(Link& link, const std::string& why, int64_t now);
  void write_all(Link& link, std::vector<Bytes>& out, bool rumble, int64_t now);
  void publish(Link& link, int64_t now);
  void name_short_report(Link& link, std::span<const uint8_t> report, int64_t now);
  void notice(const Link& link, int64_t now, std::string text);
  void pen_notice(int64_t now, std::string text);

  Backend& backend_;
  LogWriter& log_;
  std::vector<RemoteAssignment> assigned_;
  DriverOptions options_;
  Clock clock_;
  std::vector<std::unique_ptr<Link>> links_;
  std::mutex backend_mutex_;
  mutable std::mutex feedback_mutex_;
  PenFeedback feedback_;
  mutable std::mutex notices_mutex_;
  std::vector<Notice> notices_;
  std::atomic<bool> stopping_{false};
  std::vector<std::thread> threads_;
};

}  // namespace fire::wiimote
