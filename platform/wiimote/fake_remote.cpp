#include "platform/wiimote/fake_remote.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace fire::wiimote {
namespace {

// How long a read waits in real time for a queued answer. The stream itself runs on the fake's
// clock, so waiting longer would only slow tests down.
constexpr int kMaxRealWaitMs = 2;

// A backlog larger than this is dropped, as a remote's small buffer would.
constexpr int kMaxBacklogReports = 32;

class FakeHandle : public Device {
 public:
  FakeHandle(std::shared_ptr<FakeRemote> remote, uint64_t generation)
      : remote_(std::move(remote)), generation_(generation) {}
  Status write(std::span<const uint8_t> report) override { return remote_->host_write(generation_, report); }
  ReadResult read(int timeout_ms) override { return remote_->host_read(generation_, timeout_ms); }

 private:
  std::shared_ptr<FakeRemote> remote_;
  uint64_t generation_;
};

}  // namespace

// The strict reading of the notes: a memory write is always answered; 0x11-0x14, 0x19 and 0x1A only when
// their first payload byte asks (0x02); nothing else.
bool answered(uint8_t id, uint8_t flags) {
  if (id == kOutWriteMemory) return true;
  const bool may_ask = id == kOutLeds || id == kOutReportingMode || id == kOutIrPixelClock || id == 0x14 ||
                       id == 0x19 || id == kOutIrLogic;
  return may_ask && (flags & kAckRequestBit);
}

bool valid_data_mode(uint8_t mode) { return (mode >= 0x30 && mode <= 0x37) || (mode >= 0x3D && mode <= 0x3F); }

uint64_t seed_of(const FakeRemoteOptions& o) {
  if (o.schedule.seed) return o.schedule.seed;
  return std::hash<std::string>{}(normalize_address(o.address));
}

FakeRemote::FakeRemote(FakeRemoteOptions options, Clock clock)
    : options_(std::move(options)), clock_(std::move(clock)), schedule_rng_(seed_of(options_)) {
  power_on_locked();
}

double FakeRemote::uniform_locked() { return std::uniform_real_distribution<double>(0, 1)(schedule_rng_); }

void FakeRemote::power_on_locked() {
  leds_ = 0;
  rumble_ = false;
  mode_ = kInButtons;
  continuous_ = false;
  pixel_clock_ = logic_ = false;
  block1_ = block2_ = false;
  registers_.clear();
  configured_ = false;
  bad_active_ = BadState::None;
  buttons_ = 0;
  slot_fixed_.fill(false);
  extension_ = false;
  queue_.clear();
  answers_.clear();
  held_.clear();
  const int64_t now = clock_();
  const FakeSchedule& f = options_.schedule;
  next_battery_ns_ = f.battery_step_ns > 0 ? now + f.battery_step_ns : -1;
  next_extension_ns_ = f.extension_every_ns > 0 ? now + f.extension_every_ns : -1;
}

void FakeRemote::set_blob_source(BlobSource source) {
  std::lock_guard lock(mutex_);
  blobs_ = std::move(source);
}

void FakeRemote::set_buttons(uint16_t buttons) {
  std::lock_guard lock(mutex_);
  const bool changed = buttons != buttons_;
  buttons_ = buttons;
  if (changed && plugged_ && !continuous_) answer_locked(data_report_locked(clock_()));
}

void FakeRemote::drop_acks(uint8_t id, int count) {
  std::lock_guard lock(mutex_);
  drop_acks_[id] += count;
}

void FakeRemote::set_never_ack(bool never) {
  std::lock_guard lock(mutex_);
  never_ack_ = never;
}

void FakeRemote::start_in_bad_state(BadState state, uint64_t seed) {
  std::lock_guard lock(mutex_);
  if (state == BadState::Random) {
    rng_.seed(seed);
    state = (rng_() & 1) ? BadState::NoIr : BadState::WrongMode;
  }
  bad_ = state;
}

void FakeRemote::send_status() {
  std::lock_guard lock(mutex_);
  if (plugged_) status_locked();
}

void FakeRemote::extension_event() {
  std::lock_guard lock(mutex_);
  if (plugged_) extension_locked();
}

void FakeRemote::inject(Bytes report) {
  std::lock_guard lock(mutex_);
  if (plugged_) queue_locked(std::move(report));
}

void FakeRemote::hold_reports(bool hold) {
  std::lock_guard lock(mutex_);
  hold_ = hold;
  if (!hold) {
    for (Bytes& r : held_) queue_.push_back(std::move(r));
    held_.clear();
    arrived_.notify_all();
  }
}

void FakeRemote::unplug() {
  std::lock_guard lock(mutex_);
  plugged_ = false;
  ++generation_;
  queue_.clear();
  answers_.clear();
  held_.clear();
  arrived_.notify_all();
}

void FakeRemote::plug_in() {
  std::lock_guard lock(mutex_);
  if (plugged_) return;
  plugged_ = true;
  ++generation_;
  power_on_locked();
}

bool FakeRemote::plugged() const {
  std::lock_guard lock(mutex_);
  return plugged_;
}
std::vector<Bytes> FakeRemote::writes() const {
  std::lock_guard lock(mutex_);
  return writes_;
}
uint8_t FakeRemote::leds() const {
  std::lock_guard lock(mutex_);
  return leds_;
}
bool FakeRemote::rumbling() const {
  std::lock_guard lock(mutex_);
  return rumble_;
}
uint8_t FakeRemote::reporting_mode() const {
  std::lock_guard lock(mutex_);
  return mode_;
}
bool FakeRemote::continuous() const {
  std::lock_guard lock(mutex_);
  return continuous_;
}
bool FakeRemote::camera_working() const {
  std::lock_guard lock(mutex_);
  return camera_working_locked();
}
int FakeRemote::initialisations() const {
  std::lock_guard lock(mutex_);
  return initialisations_;
}
size_t FakeRemote::reports_streamed() const {
  std::lock_guard lock(mutex_);
  return streamed_;
}
uint8_t FakeRemote::register_at(uint32_t address) const {
  std::lock_guard lock(mutex_);
  const auto it = registers_.find(address);
  return it == registers_.end() ? 0 : it->second;
}
uint8_t FakeRemote::battery() const {
  std::lock_guard lock(mutex_);
  return options_.battery;
}
int FakeRemote::refused_camera_writes() const {
  std::lock_guard lock(mutex_);
  return refused_camera_writes_;
}
uint64_t FakeRemote::generation() const {
  std::lock_guard lock(mutex_);
  return generation_;
}

bool FakeRemote::camera_working_locked() const {
  const auto reg = [&](uint32_t a) {
    const auto it = registers_.find(a);
    return it == registers_.end() ? -1 : int{it->second};
  };
  return configured_ && bad_active_ == BadState::None && pixel_clock_ && logic_ && block1_ && block2_ &&
         reg(kRegIrControl) == kIrControlEnable && reg(kRegIrMode) == kIrModeExtended;
}

void FakeRemote::queue_locked(Bytes report) {
  queue_.push_back(std::move(report));
  arrived_.notify_all();
}

void FakeRemote::answer_locked(Bytes report, int64_t extra_ns) {
  const FakeSchedule& f = options_.schedule;
  const int64_t jitter = f.jitter_ns > 0 ? static_cast<int64_t>(uniform_locked() * double(f.jitter_ns)) : 0;
  // The radio keeps a remote's reports in order: a late one holds back those after it.
  last_answer_ns_ = std::max(last_answer_ns_, clock_() + f.latency_ns + jitter + extra_ns);
  answers_.emplace_back(last_answer_ns_, std::move(report));
}

void FakeRemote::ack_locked(uint8_t id, uint8_t error) {
  if (never_ack_) return;
  auto it = drop_acks_.find(id);
  if (it != drop_acks_.end() && it->second > 0) {
    --it->second;
    return;
  }
  const FakeSchedule& f = options_.schedule;
  if (f.ack_drop > 0 && uniform_locked() < f.ack_drop) return;
  int64_t late = 0;
  if (f.ack_late > 0 && uniform_locked() < f.ack_late)
    late = f.late_min_ns + static_cast<int64_t>(uniform_locked() * double(f.late_max_ns - f.late_min_ns));
  answer_locked({kInAck, uint8_t(buttons_ >> 8), uint8_t(buttons_), id, error}, late);
}

void FakeRemote::status_locked() {
  const uint8_t flags = static_cast<uint8_t>(leds_ | (pixel_clock_ ? kStatusCameraOn : 0) |
                                             (extension_ ? kStatusExtension : 0) |
                                             (options_.battery < 0x20 ? kStatusBatteryLow : 0));
  answer_locked({kInStatus, uint8_t(buttons_ >> 8), uint8_t(buttons_), flags, 0x00, 0x00, options_.battery});
  continuous_ = false;  // the trap the notes describe: reporting stops until 0x12 is sent again
}

void FakeRemote::extension_locked() {
  extension_ = !extension_;
  // The camera loses power and its registers with it, as Dolphin's does.
  pixel_clock_ = logic_ = false;
  block1_ = block2_ = false;
  registers_.clear();
  configured_ = false;
  status_locked();
}

void FakeRemote::run_schedule_locked(int64_t now) {
  const FakeSchedule& f = options_.schedule;
  if (next_battery_ns_ >= 0 && now >= next_battery_ns_) {
    next_battery_ns_ = now + f.battery_step_ns;
    if (options_.battery > 0) --options_.battery;
    status_locked();
  }
  if (next_extension_ns_ >= 0 && now >= next_extension_ns_) {
    next_extension_ns_ = now + f.extension_every_ns;
    extension_locked();
  }
}

Status FakeRemote::host_write(uint64_t generation, std::span<const uint8_t> r) {
  std::lock_guard lock(mutex_);
  if (!plugged_ || generation != generation_) return Status::failure("the remote is gone (switched off or out of range)");
  writes_.emplace_back(r.begin(), r.end());
  if (r.size() < 2) return Status::success();  // nothing a remote can act on
  const uint8_t id = r[0], flags = r[1];
  const FakeSchedule& f = options_.schedule;
  if (answered(id, flags) && f.busy > 0 && uniform_locked() < f.busy) {
    ack_locked(id, kAckBusy);  // not acted on: the host must send it again
    return Status::success();
  }
  rumble_ = flags & kRumbleBit;
  switch (id) {
    case kOutLeds:
      leds_ = flags & kLedBits;
      break;
    case kOutReportingMode:
      if (r.size() < 3 || !valid_data_mode(r[2])) break;  // a mode no remote has: ignored
      continuous_ = flags & kEnableBit;
      mode_ = r[2];
      next_report_ns_ = clock_() + options_.phase_ns;
      if (configured_ || (pixel_clock_ && logic_ && block1_ && block2_)) {
        if (!configured_) ++initialisations_;
        configured_ = true;
      }
      break;
    case kOutIrPixelClock:
      pixel_clock_ = flags & kEnableBit;
      // A new set-up starts here: a camera that came up wrong works after being set up again.
      if (configured_) bad_active_ = BadState::None;
      configured_ = false;
      if (bad_ != BadState::None) {
        bad_active_ = bad_;
        bad_ = BadState::None;
      }
      break;
    case kOutIrLogic:
      logic_ = flags & kEnableBit;
      break;
    case kOutStatusRequest:
      status_locked();
      return Status::success();
    case kOutWriteMemory:
      if (r.size() < 6) return Status::success();
      if (flags & kEnableBit) {
        const uint32_t address = uint32_t{r[2]} << 16 | uint32_t{r[3]} << 8 | r[4];
        if ((address >> 16) == (kRegIrControl >> 16) && !(pixel_clock_ && logic_)) {
          ++refused_camera_writes_;
          ack_locked(id, kAckNoCamera);  // the camera is off and does not answer
          return Status::success();
        }
        const size_t n = std::min<size_t>(r[5], r.size() - 6);
        for (size_t k = 0; k < n; ++k) registers_[address + static_cast<uint32_t>(k)] = r[6 + k];
        if (address == kRegIrBlock1 && n == 9) block1_ = true;
        if (address == kRegIrBlock2 && n == 2) block2_ = true;
      }
      ack_locked(id, 0);  // a memory write is always answered
      return Status::success();
    default:
      break;
  }
  if (answered(id, flags)) ack_locked(id, 0);
  return Status::success();
}

Bytes FakeRemote::data_report_locked(int64_t t_ns) {
  const uint8_t mode = bad_active_ == BadState::WrongMode && configured_ ? uint8_t{0x31} : mode_;
  if (mode != kInIrExtended) {
    const size_t size = input_report_size(mode);
    Bytes out(size ? size : 3, 0);
    out[0] = size ? mode : kInButtons;
    out[1] = uint8_t(buttons_ >> 8);
    out[2] = uint8_t(buttons_);
    return out;
  }
  IrReport report{.report_id = kInIrExtended,
                  .buttons = {uint8_t(buttons_ >> 8), uint8_t(buttons_)},
                  .accel = {uint8_t(streamed_ >> 16), uint8_t(streamed_ >> 8), uint8_t(streamed_)},
                  .slots = {}};
  if (camera_working_locked() && blobs_) report.slots = blobs_(t_ns);
  Bytes out = encode_ir_report(report);
  for (size_t k = 0; k < kIrSlots; ++k) {
    slot_fixed_[k] = slot_fixed_[k] || report.slots[k].seen;
    if (!slot_fixed_[k]) std::fill_n(out.begin() + 6 + 3 * static_cast<std::ptrdiff_t>(k), 3, uint8_t{0});
  }
  return out;
}

ReadResult FakeRemote::host_read(uint64_t generation, int timeout_ms) {
  std::unique_lock lock(mutex_);
  const auto gone = [&] {
    return ReadResult{.status = ReadStatus::Gone, .report = {}, .error = "the remote is gone (switched off or out of range)"};
  };
  for (int pass = 0; pass < 2; ++pass) {
    if (!plugged_ || generation != generation_) return gone();
    const int64_t now = clock_();
    run_schedule_locked(now);
    const int64_t period = options_.rate_hz > 0 ? static_cast<int64_t>(std::llround(1e9 / options_.rate_hz)) : 0;
    if (continuous_ && period > 0 && now - next_report_ns_ > kMaxBacklogReports * period)
      next_report_ns_ = now - kMaxBacklogReports * period;
    // The stream and the answers on the radio, in the order of their instants.
    for (;;) {
      const bool stream_due = continuous_ && period > 0 && next_report_ns_ <= now;
      const bool answer_due = !answers_.empty() && answers_.front().first <= now;
      if (answer_due && (!stream_due || answers_.front().first <= next_report_ns_)) {
        queue_.push_back(std::move(answers_.front().second));
        answers_.pop_front();
      } else if (stream_due) {
        Bytes r = data_report_locked(next_report_ns_);
        ++streamed_;
        next_report_ns_ += period;
        (hold_ ? held_ : queue_).push_back(std::move(r));
      } else {
        break;
      }
    }
    if (!queue_.empty()) {
      ReadResult out{.status = ReadStatus::Report, .report = std::move(queue_.front()), .error = {}};
      queue_.pop_front();
      return out;
    }
    if (pass == 1 || timeout_ms <= 0) break;
    arrived_.wait_for(lock, std::chrono::milliseconds(std::min(timeout_ms, kMaxRealWaitMs)));
  }
  return ReadResult{};
}

std::shared_ptr<FakeRemote> FakeBus::add_remote(FakeRemoteOptions options) {
  auto remote = std::make_shared<FakeRemote>(std::move(options), clock_);
  std::lock_guard lock(mutex_);
  remotes_.push_back(remote);
  return remote;
}

void FakeBus::add_other_device(DeviceInfo info) {
  std::lock_guard lock(mutex_);
  others_.push_back(std::move(info));
}

void FakeBus::deny_open(const std::string& address, std::string why) {
  std::lock_guard lock(mutex_);
  if (why.empty())
    denied_.erase(address);
  else
    denied_[address] = std::move(why);
}

int FakeBus::opens(const std::string& address) const {
  std::lock_guard lock(mutex_);
  const auto it = opens_.find(address);
  return it == opens_.end() ? 0 : it->second;
}

Result<std::vector<DeviceInfo>> FakeBus::enumerate() {
  std::lock_guard lock(mutex_);
  std::vector<DeviceInfo> out;
  for (const auto& r : remotes_)
    if (r->plugged())
      out.push_back({.vendor = kNintendoVendor, .product = r->options().product, .serial = r->options().address,
                     .path = "fake:" + r->options().address,
                     .product_name = !r->options().name.empty()                  ? r->options().name
                                     : r->options().product == kProductRemotePlus ? "Nintendo RVL-CNT-01-TR"
                                                                                  : "Nintendo RVL-CNT-01"});
  out.insert(out.end(), others_.begin(), others_.end());
  // Real enumeration order changes from one call to the next; so does this one's.
  if (!out.empty()) std::rotate(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(rotation_++ % out.size()), out.end());
  return out;
}

Result<std::unique_ptr<Device>> FakeBus::open(const DeviceInfo& info) {
  using R = Result<std::unique_ptr<Device>>;
  std::lock_guard lock(mutex_);
  for (const auto& r : remotes_) {
    if ("fake:" + r->options().address != info.path) continue;
    if (!r->plugged()) return R::failure(info.path + ": no such device (switched off?)");
    const auto denied = denied_.find(r->options().address);
    if (denied != denied_.end()) return R::failure(info.path + ": " + denied->second);
    ++opens_[r->options().address];
    return R(std::make_unique<FakeHandle>(r, r->generation()));
  }
  return R::failure(info.path + ": not a device on this bus");
}

}  // namespace fire::wiimote
