#pragma once
// A fake Wii Remote and a fake bus to plug it into, for tests and simulations. The remote is as
// strict as a real one (shared/wiimote-protocol.md, the kernel's hid-wiimote, Dolphin): it
// acknowledges 0x11-0x14, 0x19 and 0x1A only when their first payload byte asks for it (0x02),
// always answers a memory write (0x16), refuses a camera register write with error 7 while the
// camera is off, ignores a reporting mode no remote has, stops continuous reporting after every
// status report (0x20) until it is sent 0x12 again, and its IR camera shows objects only once it has
// been initialised as the notes say. Its answers come after a radio latency with jitter, never
// inside the write. Its empty IR slots read 00 00 00 until each first sees light, then FF FF FF. On
// its own (seeded) schedule its battery drains, each step announced by a 0x20, and it may drop or
// delay acknowledgements and plug an extension, which switches the camera off. It streams reports
// on its own injected clock, so tests run faster than real time; a test scripts further faults.
// The accelerometer bytes of its 0x33 reports hold a frame counter (big-endian), so a test can see
// whether reports were lost or reordered on their way to the log.
#include <array>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <random>

#include "platform/wiimote/device.hpp"

namespace fire::wiimote {

// A clock that moves only when told to; shared by the fakes and the driver in tests.
class ManualClock {
 public:
  explicit ManualClock(int64_t start_ns = 0) : now_(start_ns) {}
  int64_t now() const { return now_.load(); }
  void advance(int64_t ns) { now_ += ns; }
  Clock clock() {
    return [this] { return now_.load(); };
  }

 private:
  std::atomic<int64_t> now_;
};

// What the camera sees at a time on the remote's clock.
using BlobSource = std::function<IrSlots(int64_t t_ns)>;

enum class BadState : uint8_t {
  None,
  NoIr,       // the camera stays dark after its first initialisation
  WrongMode,  // the remote streams 0x31 whatever mode it is asked for, until initialised again
  Random,     // one of the two, drawn from the seed
};

// What the remote does on its own; the defaults are a healthy remote's, with a battery that drains.
struct FakeSchedule {
  uint64_t seed = 0;               // 0: drawn from the address
  int64_t latency_ns = 2'000'000;  // from a write to its answer...
  int64_t jitter_ns = 2'000'000;   // ... plus up to this much more
  double ack_drop = 0;             // fraction of acknowledgements lost on the radio
  double ack_late = 0;             // fraction that come late, between late_min_ns and late_max_ns
  int64_t late_min_ns = 300'000'000, late_max_ns = 900'000'000;  // within the kernel's 1 s
  double busy = 0;                 // fraction of writes answered with error 4 (busy) instead
  int64_t battery_step_ns = 30'000'000'000;  // one battery unit lost (and a 0x20 sent) this often; 0: never
  int64_t extension_every_ns = 0;  // an extension plugged in or pulled out this often (camera off); 0: never
};

struct FakeRemoteOptions {
  std::string address = "00:1F:32:00:00:01";
  uint16_t product = kProductRemote;
  std::string name{};        // the product name the bus lists; empty: the Wii Remote's for `product`
  double rate_hz = 100;
  int64_t phase_ns = 0;      // first report instant after reporting starts
  uint8_t battery = 0xA0;
  FakeSchedule schedule{};
};

class FakeRemote {
 public:
  FakeRemote(FakeRemoteOptions options, Clock clock);

  const FakeRemoteOptions& options() const { return options_; }

  // --- scripting ---
  void set_blob_source(BlobSource source);
  // The next `count` acknowledgements of report `id` are lost.
  void drop_acks(uint8_t id, int count);
  // Never acknowledges anything (not even memory writes): a remote FIRE cannot start.
  void set_never_ack(bool never);
  // The next initialisation of the camera goes wrong as `state` says; the one after works.
  void start_in_bad_state(BadState state, uint64_t seed = 0);
  // A status report arrives unasked; continuous reporting stops.
  void send_status();
  // An extension is plugged in (or pulled out): a status report, and the camera is switched off.
  void extension_event();
  // An arbitrary input report (garbage, truncated, another id) is queued for the host.
  void inject(Bytes report);
  // The buttons held now (kButton* bits): every report that carries buttons shows them, and a change is
  // reported at once unless the remote streams continuously, as the hardware does.
  void set_buttons(uint16_t buttons);
  // While held, reports pile up; on release they reach the host together, late.
  void hold_reports(bool hold);
  // Switched off: open handles fail and the bus no longer lists it. Plugging it back in is a
  // fresh power-on: registers cleared, LEDs off, no reporting until asked.
  void unplug();
  void plug_in();

  // --- what the remote has seen and done ---
  bool plugged() const;
  std::vector<Bytes> writes() const;  // every output report received, in order
  uint8_t leds() const;
  bool rumbling() const;
  uint8_t reporting_mode() const;
  bool continuous() const;
  bool camera_working() const;     // initialised as the notes say and not in a bad state
  int initialisations() const;     // 0x12 reports received after a full camera set-up
  size_t reports_streamed() const; // data reports produced by the stream
  uint8_t register_at(uint32_t address) const;
  uint8_t battery() const;
  int refused_camera_writes() const;  // memory writes answered with error 7

  // --- the host side, used by the bus's device handles ---
  uint64_t generation() const;
  Status host_write(uint64_t generation, std::span<const uint8_t> report);
  ReadResult host_read(uint64_t generation, int timeout_ms);

 private:
  void power_on_locked();
  void queue_locked(Bytes report);
  void answer_locked(Bytes report, int64_t extra_ns = 0);
  void ack_locked(uint8_t id, uint8_t error);
  void status_locked();
  void extension_locked();
  void run_schedule_locked(int64_t now);
  double uniform_locked();
  Bytes data_report_locked(int64_t t_ns);
  bool camera_working_locked() const;

  FakeRemoteOptions options_;
  Clock clock_;
  mutable std::mutex mutex_;
  std::condition_variable arrived_;
  BlobSource blobs_;
  bool plugged_ = true;
  uint64_t generation_ = 1;
  std::deque<Bytes> queue_;
  std::deque<std::pair<int64_t, Bytes>> answers_;  // on the radio: delivered at their instant, in order
  int64_t last_answer_ns_ = 0;
  std::deque<Bytes> held_;
  bool hold_ = false;
  std::vector<Bytes> writes_;
  std::map<uint8_t, int> drop_acks_;
  bool never_ack_ = false;
  BadState bad_ = BadState::None;
  std::mt19937_64 rng_;
  std::mt19937_64 schedule_rng_;
  int64_t next_battery_ns_ = -1, next_extension_ns_ = -1;
  bool extension_ = false;
  int refused_camera_writes_ = 0;
  // Device state, reset by power_on_locked.
  uint8_t leds_ = 0;
  bool rumble_ = false;
  uint8_t mode_ = kInButtons;
  bool continuous_ = false;
  bool pixel_clock_ = false;
  bool logic_ = false;
  bool block1_ = false, block2_ = false;
  std::map<uint32_t, uint8_t> registers_;
  bool configured_ = false;   // set-up complete when 0x12 arrived
  BadState bad_active_ = BadState::None;  // how the current initialisation went wrong
  uint16_t buttons_ = 0;
  std::array<bool, kIrSlots> slot_fixed_{};  // a slot reads 00 00 00 when empty until it first sees light
  int initialisations_ = 0;
  int64_t next_report_ns_ = 0;
  size_t streamed_ = 0;
};

// Lists the remotes plugged into it (in an order that changes between calls, as real
// enumeration does) and any other HID device a test adds.
class FakeBus : public Backend {
 public:
  explicit FakeBus(Clock clock) : clock_(std::move(clock)) {}
  std::shared_ptr<FakeRemote> add_remote(FakeRemoteOptions options);
  void add_other_device(DeviceInfo info);
  // open() of this address fails with `why` (e.g. permission denied); empty `why` allows it again.
  void deny_open(const std::string& address, std::string why);
  int opens(const std::string& address) const;

  Result<std::vector<DeviceInfo>> enumerate() override;
  Result<std::unique_ptr<Device>> open(const DeviceInfo& info) override;

 private:
  Clock clock_;
  mutable std::mutex mutex_;
  std::vector<std::shared_ptr<FakeRemote>> remotes_;
  std::vector<DeviceInfo> others_;
  std::map<std::string, std::string> denied_;
  std::map<std::string, int> opens_;
  size_t rotation_ = 0;
};

}  // namespace fire::wiimote
