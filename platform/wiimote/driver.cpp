#include "platform/wiimote/driver.hpp"

#include <chrono>
#include <cstdio>
#include <set>

namespace fire::wiimote {

std::string_view link_state_name(LinkState state) {
  switch (state) {
    case LinkState::Missing: return "missing";
    case LinkState::Starting: return "starting";
    case LinkState::Running: return "running";
    case LinkState::Failed: return "failed";
  }
  return "?";
}

struct Driver::Link {
  Link(Role r, std::string a, StartupOptions o) : role(r), address(std::move(a)), machine(r, o) {}
  Role role;
  std::string address;
  DeviceInfo info;
  // Touched only by the link's own thread (or by poll while no thread runs).
  std::unique_ptr<Device> device;
  RemoteMachine machine;
  int sent_leds = -1;  // unknown until the first LED report goes out
  bool sent_rumble = false;
  int64_t next_reopen = 0;
  std::string missing_why = "not found";
  std::string last_warning;
  MachineState last_state = MachineState::Starting;
  std::set<uint8_t> named_short;  // report ids already named for coming shorter than their layout
  // What other threads may read.
  mutable std::mutex mutex;
  RemoteView view;
};

Driver::Driver(Backend& backend, LogWriter& log, std::vector<RemoteAssignment> assigned, DriverOptions options,
               Clock clock)
    : backend_(backend),
      log_(log),
      assigned_(std::move(assigned)),
      options_(options),
      clock_(std::move(clock)),
      feedback_(options.feedback) {}

Driver::~Driver() { stop(); }

Result<Scan> Driver::open_all() {
  if (!links_.empty() || !threads_.empty()) return Result<Scan>::failure("the remotes are already open");
  Result<std::vector<DeviceInfo>> found = [&] {
    std::lock_guard lock(backend_mutex_);
    return backend_.enumerate();
  }();
  if (!found) return Result<Scan>::failure(found.error());
  Scan scan;
  const int64_t now = clock_();
  for (const DeviceInfo& info : *found) {
    if (!is_wii_remote(info)) {
      scan.not_remotes.push_back(info);
      continue;
    }
    const std::optional<Role> role = role_of(info.serial, assigned_, *found);
    bool taken = false;
    for (const auto& l : links_) taken |= role && l->role == *role;
    if (!role || taken) {
      scan.unassigned.push_back(info);
      continue;
    }
    links_.push_back(std::make_unique<Link>(*role, normalize_address(info.serial), options_.startup));
    Link& link = *links_.back();
    link.info = info;
    reopen(link, now);
    if (!link.device) scan.open_errors.push_back(link.missing_why);
  }
  // Roles whose remote is not here yet: looked for while the driver runs.
  for (const RemoteAssignment& a : assigned_) {
    bool have = false;
    for (const auto& l : links_) have |= l->role == a.role;
    if (have) continue;
    links_.push_back(std::make_unique<Link>(a.role, a.address, options_.startup));
    Link& link = *links_.back();
    link.next_reopen = now + options_.reopen_every_ns;
    notice(link, now, "not found; waiting for it to be switched on");
    publish(link, now);
  }
  return scan;
}

void Driver::notice(const Link& link, int64_t now, std::string text) {
  std::lock_guard lock(notices_mutex_);
  notices_.push_back({.t_ns = now, .device = log_device(link.role), .address = link.address, .text = std::move(text)});
}

void Driver::pen_notice(int64_t now, std::string text) {
  std::lock_guard lock(notices_mutex_);
  notices_.push_back({.t_ns = now, .device = kPenNotice, .address = {}, .text = std::move(text)});
}

std::string describe(const Notice& n) {
  if (n.device == kPenNotice) return "pen: " + n.text;
  return "remote " + std::to_string(n.device) + " " + n.address + ": " + n.text;
}

std::string describe(const RemoteView& v) {
  std::string line = std::string(role_name(v.role)) + " " + v.address + ": " + std::string(link_state_name(v.state));
  if (v.status) {
    line += ", battery " + std::to_string(battery_percent(*v.status)) + "%";
    if (v.status->battery_low()) line += " LOW";
  }
  if (!v.error.empty()) line += " (" + v.error + ")";
  else if (!v.warning.empty()) line += " (" + v.warning + ")";
  return line;
}

void Driver::reopen(Link& link, int64_t now) {
  link.next_reopen = now + options_.reopen_every_ns;
  Result<std::unique_ptr<Device>> opened = Result<std::unique_ptr<Device>>::failure("not found");
  {
    std::lock_guard lock(backend_mutex_);
    const Result<std::vector<DeviceInfo>> found = backend_.enumerate();
    if (!found) {
      link.missing_why = found.error();
    } else {
      bool present = false;
      for (const DeviceInfo& info : *found) {
        if (!is_wii_remote(info) || normalize_address(info.serial) != link.address) continue;
        present = true;
        link.info = info;
        opened = backend_.open(info);
        break;
      }
      if (present && !opened) link.missing_why = opened.error();
      if (!present) link.missing_why = "not found";
    }
  }
  if (!opened) {
    publish(link, now);
    return;
  }
  link.device = std::move(*opened);
  link.sent_leds = -1;
  link.sent_rumble = false;
  char product[8];
  std::snprintf(product, sizeof product, "%04x", link.info.product);
  const int device = log_device(link.role);
  log_.meta("device", std::to_string(device) + " " + link.address + " " + std::string(role_name(link.role)) + " " + product);
  notice(link, now, "opened " + link.info.path);
  uint8_t leds = 0;
  {
    std::lock_guard lock(feedback_mutex_);
    if (is_camera(link.role)) feedback_.camera_available(device, true, now);
    leds = feedback_.leds(link.role);
  }
  std::vector<Bytes> out;
  link.machine.begin(now, leds, out);
  link.last_state = MachineState::Starting;
  write_all(link, out, false, now);
  publish(link, now);
}

void Driver::lose(Link& link, const std::string& why, int64_t now) {
  link.device.reset();
  link.missing_why = "lost: " + why;
  link.next_reopen = now + options_.reopen_every_ns;
  const int device = log_device(link.role);
  log_.meta("device_lost", std::to_string(device) + " " + link.address + " " + why);
  notice(link, now, "lost (" + why + "); it is reopened when it comes back");
  if (is_camera(link.role)) {
    std::vector<std::string> events;
    bool was_down = false;
    {
      std::lock_guard lock(feedback_mutex_);
      was_down = feedback_.pen_down();
      feedback_.camera_available(device, false, now);
      events = feedback_.take_events();
    }
    if (was_down) notice(link, now, "the stroke ended: camera " + std::to_string(device) + " is gone");
    for (std::string& e : events) pen_notice(now, std::move(e));
  }
  publish(link, now);
}

void Driver::write_all(Link& link, std::vector<Bytes>& out, bool rumble, int64_t now) {
  for (Bytes& report : out) {
    if (!link.device) return;
    // Bit 0 of every output report drives the motor: set only for the pad, and only as wanted.
    if (report.size() >= 2) report[1] = static_cast<uint8_t>((report[1] & ~kRumbleBit) | (rumble ? kRumbleBit : 0));
    const Status written = link.device->write(report);
    if (!written) {
      lose(link, written.error, now);
      return;
    }
    link.sent_rumble = rumble;
    if (report[0] == kOutLeds && report.size() >= 2) link.sent_leds = report[1] & kLedBits;
  }
  out.clear();
}

void Driver::publish(Link& link, int64_t now) {
  const MachineState state = link.machine.state();
  if (link.device) {
    if (state != link.last_state) {
      if (state == MachineState::Running) notice(link, now, "running");
      if (state == MachineState::Failed) notice(link, now, "failed: " + link.machine.error());
      link.last_state = state;
    }
    if (link.machine.warning() != link.last_warning) {
      if (!link.machine.warning().empty()) notice(link, now, link.machine.warning());
      link.last_warning = link.machine.warning();
    }
  }
  std::lock_guard lock(link.mutex);
  RemoteView& v = link.view;
  v.device = log_device(link.role);
  v.role = link.role;
  v.address = link.address;
  v.product = link.info.product;
  v.status = link.machine.status();
  if (!link.device) {
    v.state = LinkState::Missing;
    v.error = link.missing_why;
    v.warning.clear();
    return;
  }
  v.state = state == MachineState::Running ? LinkState::Running
            : state == MachineState::Failed ? LinkState::Failed
                                            : LinkState::Starting;
  v.error = link.machine.error();
  v.warning = link.machine.warning();
}

bool Driver::step(Link& link, int read_timeout_ms) {
  if (!link.device) {
    const int64_t now = clock_();
    if (now < link.next_reopen) return false;
    reopen(link, now);
    return link.device != nullptr;
  }
  ReadResult r = link.device->read(read_timeout_ms);
  const int64_t now = clock_();
  std::vector<Bytes> out;
  const int device = log_device(link.role);
  if (r.status == ReadStatus::Gone) {
    lose(link, r.error, now);
    return true;
  }
  std::optional<int> objects;
  // hidapi never returns an empty report (0 bytes is its timeout); the log cannot hold one either.
  if (r.status == ReadStatus::Report && !r.report.empty()) {
    // Stamped with when the read returned, not when the log's lock was free (a live log keeps its order).
    log_.hid(device, r.report, now);
    link.machine.on_report(r.report, now, out);
    name_short_report(link, r.report, now);
    if (is_camera(link.role) && link.machine.state() == MachineState::Running) objects = ir_blob_count(r.report);
  }
  link.machine.tick(now, out);
  uint8_t leds = 0;
  bool rumble = false;
  std::vector<std::string> events;
  bool stroke_ended = false;
  {
    std::lock_guard lock(feedback_mutex_);
    const bool was_down = feedback_.pen_down();
    if (objects) feedback_.camera_report(device, *objects > 0, now);
    feedback_.tick(now);
    stroke_ended = was_down && !feedback_.pen_down();
    leds = feedback_.leds(link.role);
    rumble = link.role == Role::CommandPad && feedback_.rumble(now);
    events = feedback_.take_events();
  }
  if (stroke_ended) pen_notice(now, "the stroke ended");
  for (std::string& e : events) pen_notice(now, std::move(e));
  link.machine.set_leds(leds);
  // The start-up sets the LEDs itself; after it, they follow the feedback.
  if (link.machine.state() != MachineState::Starting && (leds != link.sent_leds || rumble != link.sent_rumble))
    out.push_back(leds_report(leds, false));
  write_all(link, out, rumble, now);
  publish(link, now);
  return r.status == ReadStatus::Report;
}

void Driver::name_short_report(Link& link, std::span<const uint8_t> report, int64_t now) {
  const size_t expected = input_report_size(report[0]);
  if (report.size() >= expected || link.named_short.contains(report[0])) return;
  link.named_short.insert(report[0]);
  char text[128];
  std::snprintf(text, sizeof text, "report 0x%02X has %zu bytes, its layout %zu: kept in the log, not read (named once)",
                report[0], report.size(), expected);
  notice(link, now, text);
}

void Driver::poll(int read_timeout_ms) {
  for (auto& link : links_) step(*link, read_timeout_ms);
}

void Driver::start() {
  if (!threads_.empty()) return;
  stopping_ = false;
  for (auto& link : links_) {
    threads_.emplace_back([this, l = link.get()] {
      while (!stopping_) {
        // A missing remote is looked for on the driver's clock; this only keeps the thread idle.
        if (!step(*l, options_.read_timeout_ms) && !l->device) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
    });
  }
}

void Driver::stop() {
  stopping_ = true;
  for (std::thread& t : threads_) t.join();
  threads_.clear();
}

std::vector<RemoteView> Driver::remotes() const {
  std::vector<RemoteView> out;
  for (const auto& link : links_) {
    std::lock_guard lock(link->mutex);
    out.push_back(link->view);
  }
  return out;
}

int Driver::cameras(std::optional<LinkState> state) const {
  int count = 0;
  for (const RemoteView& v : remotes())
    count += is_camera(v.role) && (state ? v.state == *state : v.state != LinkState::Missing);
  return count;
}

std::vector<Notice> Driver::take_notices() {
  std::lock_guard lock(notices_mutex_);
  std::vector<Notice> out;
  out.swap(notices_);
  return out;
}

bool Driver::pen_down() const {
  std::lock_guard lock(feedback_mutex_);
  return feedback_.pen_down();
}

}  // namespace fire::wiimote
