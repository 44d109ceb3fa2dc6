// What `fire devices` names after its table: each step missed, one line, in the order of docs/hardware.md.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "platform/wiimote/fake_remote.hpp"
#include "platform/wiimote/missed_steps.hpp"

using namespace fire;
using namespace fire::wiimote;

namespace {

constexpr const char* kA = "00:1F:32:AA:BB:01";
constexpr const char* kB = "00:1F:32:AA:BB:02";
constexpr const char* kC = "00:1F:32:AA:BB:03";
constexpr const char* kD = "00:1F:32:AA:BB:04";
constexpr const char* kE = "00:1F:32:AA:BB:05";

ListedRemote listed(const std::string& address, const std::string& path, ListedState state = ListedState::Ready,
                    std::optional<StatusReport> status = StatusReport{.flags = 0, .battery = 0xA0}) {
  return {.info = {.vendor = kNintendoVendor, .product = kProductRemote, .serial = address, .path = path, .product_name = {}},
          .address = address, .role = {}, .state = state, .status = status,
          .problem = state == ListedState::Ready ? "" : "what hidapi said"};
}

SysfsRemote on_sysfs(const std::string& address, SetupVerdict verdict, const std::string& hidraw) {
  return {.hid_id = "0005:057E:0306.00" + address.substr(15), .address = address, .name = "Nintendo RVL-CNT-01",
          .driver = {}, .hidraw = hidraw, .verdict = verdict, .message = address + ": the kernel's message"};
}

DevicesSeen with_adapter() {
  DevicesSeen seen;
  seen.sysfs.bluetooth_dir = "/sys/class/bluetooth";
  seen.sysfs.adapters = {{.name = "hci0", .blocked = false}};
  return seen;
}

std::vector<RemoteAssignment> rig(std::vector<std::pair<const char*, Role>> remotes) {
  std::vector<RemoteAssignment> out;
  for (const auto& [address, role] : remotes) out.push_back({.address = address, .role = role});
  return out;
}

std::vector<Step> steps_of(const std::vector<MissedStep>& steps) {
  std::vector<Step> out;
  for (const MissedStep& s : steps) out.push_back(s.step);
  return out;
}

}  // namespace

TEST_CASE("no remote at all: what sysfs shows of the adapter says why, pointing to pairing") {
  DevicesSeen seen;
  seen.sysfs.bluetooth_dir = "/sys/class/bluetooth";
  SECTION("no adapter") {
    const auto steps = missed_steps(seen);
    REQUIRE(steps.size() == 1);
    CHECK(steps[0].step == Step::Connect);
    CHECK(steps[0].line == "no Wii Remote found, and no Bluetooth adapter (none in /sys/class/bluetooth): plug in a "
                           "Bluetooth Classic adapter (docs/hardware.md section 1), then pair and connect the remotes "
                           "(docs/hardware.md section 5)");
  }
  SECTION("the adapter switched off") {
    seen.sysfs.adapters = {{.name = "hci0", .blocked = true}};
    const auto steps = missed_steps(seen);
    REQUIRE(steps.size() == 1);
    CHECK_THAT(steps[0].line, Catch::StartsWith("no Wii Remote found: the Bluetooth adapter hci0 is switched off"));
    CHECK_THAT(steps[0].line, Catch::Contains("rfkill unblock bluetooth"));
  }
  SECTION("an adapter, no rig: one line") {
    seen.sysfs.adapters = {{.name = "hci0", .blocked = true}, {.name = "hci1", .blocked = false}};
    const auto steps = missed_steps(seen);
    REQUIRE(steps.size() == 1);
    CHECK(steps[0].line == "no Wii Remote found: none is connected: pair and connect them; a paired and trusted remote "
                           "reconnects when you press a button on it (docs/hardware.md section 5)");
    CHECK_FALSE(cannot_use(steps[0].step));
  }
  SECTION("an adapter and a rig: each of its remotes, by address") {
    seen.sysfs.adapters = {{.name = "hci0", .blocked = false}};
    seen.assigned = rig({{kB, Role::Camera1}, {kA, Role::Camera0}});
    seen.rig_path = "rig.json";
    const auto steps = missed_steps(seen);
    REQUIRE(steps.size() == 2);
    CHECK(steps[0].line == std::string("camera0 ") + kA + " (rig.json) is not connected: press a button on it to reconnect "
                           "it, or pair and connect it if it was never paired on this PC (docs/hardware.md section 5)");
    CHECK_THAT(steps[1].line, Catch::StartsWith(std::string("camera1 ") + kB + " (rig.json) is not connected"));
  }
}

TEST_CASE("a remote the rig lists counts as connected when sysfs alone shows it, stuck with the kernel") {
  DevicesSeen seen = with_adapter();
  seen.assigned = rig({{kA, Role::Camera0}, {kB, Role::Camera1}});
  seen.listing.remotes = {listed(kB, "/dev/hidraw4")};
  seen.sysfs.remotes = {on_sysfs(kA, SetupVerdict::NoNode, ""), on_sysfs(kB, SetupVerdict::Ready, "hidraw4")};
  const auto steps = missed_steps(seen);
  REQUIRE(steps.size() == 1);
  CHECK(steps[0].step == Step::KernelDriver);
  CHECK(steps[0].line == std::string(kA) + ": the kernel's message");
  CHECK(cannot_use(steps[0].step));
}

TEST_CASE("every step missed at once comes in the guide's order, each remote once per step") {
  DevicesSeen seen = with_adapter();
  seen.rig_path = "rig.json";
  seen.assigned = rig({{kA, Role::Camera0}, {kE, Role::Camera1}});  // no pad: it was off while calibrating
  seen.dev_root = "/dev";
  seen.denied = [](const std::string& node) { return node == "/dev/hidraw3"; };
  // A: ready, low battery. B: hid-wiimote (hidapi refused it too). C: the user may not open it.
  // D: no answer. E, the rig's camera1: not connected.
  seen.listing.remotes = {listed(kA, "/dev/hidraw1", ListedState::Ready, StatusReport{.flags = kStatusBatteryLow, .battery = 0x18}),
                          listed(kB, "/dev/hidraw2", ListedState::CannotOpen, std::nullopt),
                          listed(kC, "/dev/hidraw3", ListedState::CannotOpen, std::nullopt),
                          listed(kD, "/dev/hidraw4", ListedState::NoAnswer, std::nullopt)};
  seen.sysfs.remotes = {on_sysfs(kA, SetupVerdict::Ready, "hidraw1"), on_sysfs(kB, SetupVerdict::KernelDriver, "hidraw2"),
                        on_sysfs(kC, SetupVerdict::Ready, "hidraw3"), on_sysfs(kD, SetupVerdict::Ready, "hidraw4")};
  const auto steps = missed_steps(seen);
  CHECK(steps_of(steps) == std::vector<Step>{Step::Connect, Step::KernelDriver, Step::Permissions, Step::Answer, Step::Battery,
                                             Step::Role, Step::Role, Step::Role});
  REQUIRE(steps.size() == 8);
  CHECK_THAT(steps[0].line, Catch::StartsWith(std::string("camera1 ") + kE + " (rig.json) is not connected"));
  CHECK(steps[1].line == std::string(kB) + ": the kernel's message");
  CHECK_THAT(steps[2].line, Catch::StartsWith(std::string(kC) + ": permission denied on /dev/hidraw3: install FIRE's udev rule"));
  CHECK_THAT(steps[2].line, Catch::Contains("sudo usermod -aG plugdev $USER"));
  CHECK_THAT(steps[2].line, Catch::EndsWith("(docs/hardware.md section 6; details: docs/wiimote.md section 3)"));
  CHECK(steps[3].line == std::string(kD) + ": what hidapi said");
  CHECK(steps[4].line == std::string("camera0 ") + kA +
                             ": its battery is low (12 %): put in fresh AA cells before the session, never during one "
                             "(docs/hardware.md section 1)");
  CHECK(steps[5].line == std::string(kB) + ": not in the \"remotes\" of rig.json, so fire app --live leaves it alone: if it "
                                           "is the pad (switched off while calibrating), add {\"address\": \"" + kB +
                             "\", \"role\": \"pad\"} to that list (docs/hardware.md section 7)");
  CHECK_THAT(steps[6].line, Catch::StartsWith(kC));
  CHECK_THAT(steps[7].line, Catch::StartsWith(kD));
}

TEST_CASE("a node is checked where hidapi listed it, or where --dev-root puts sysfs's") {
  DevicesSeen seen = with_adapter();
  seen.denied = [](const std::string&) { return true; };
  seen.listing.remotes = {listed(kA, "/dev/hidraw1", ListedState::CannotOpen, std::nullopt)};
  seen.sysfs.remotes = {on_sysfs(kA, SetupVerdict::Ready, "hidraw1"), on_sysfs(kB, SetupVerdict::Ready, "hidraw2")};
  SECTION("no dev root: only hidapi's node") {
    const auto steps = missed_steps(seen);
    REQUIRE(steps.size() == 1);
    CHECK(steps[0].step == Step::Permissions);
    CHECK_THAT(steps[0].line, Catch::StartsWith(std::string("camera0 ") + kA + ": permission denied on /dev/hidraw1"));
  }
  SECTION("a dev root: sysfs's node too") {
    seen.dev_root = "/tmp/dev";
    const auto steps = missed_steps(seen);
    CHECK(steps_of(steps) == std::vector<Step>{Step::Permissions, Step::Permissions});
    REQUIRE(steps.size() == 2);
    CHECK_THAT(steps[1].line, Catch::StartsWith(std::string("camera1 ") + kB + ": permission denied on /tmp/dev/hidraw2"));
  }
}

TEST_CASE("without a rig's remotes, three remotes or more: the roles by address order and the pad switched off") {
  DevicesSeen seen = with_adapter();
  seen.listing.remotes = {listed(kC, "/dev/hidraw3"), listed(kA, "/dev/hidraw1")};
  CHECK(missed_steps(seen).empty());
  seen.listing.remotes.push_back(listed(kB, "/dev/hidraw2"));
  auto steps = missed_steps(seen);
  REQUIRE(steps.size() == 1);
  CHECK(steps[0].step == Step::Role);
  CHECK(steps[0].line == std::string("3 Wii Remotes and no rig file, so the roles go by address order: ") + kA + " camera0, " +
                             kB + " camera1, " + kC +
                             " pad: switch the pad off while you aim and calibrate (a pad whose address sorts first would be "
                             "taken as a camera), then add it to the rig's \"remotes\" (docs/hardware.md section 7)");
  seen.sysfs.remotes = {on_sysfs(kD, SetupVerdict::NoNode, "")};
  seen.rig_path = "old-rig.json";
  steps = missed_steps(seen);
  CHECK(steps_of(steps) == std::vector<Step>{Step::KernelDriver, Step::Role});
  REQUIRE(steps.size() == 2);
  CHECK_THAT(steps[1].line, Catch::StartsWith("4 Wii Remotes and old-rig.json without \"remotes\", so the roles go by"));
  CHECK_THAT(steps[1].line, Catch::Contains(std::string(kC) + " pad, " + kD + " none (left alone):"));
}

TEST_CASE("a rig that has its pad: another remote is left alone, and the rig's pad named") {
  DevicesSeen seen = with_adapter();
  seen.rig_path = "rig.json";
  seen.assigned = rig({{kA, Role::Camera0}, {kB, Role::Camera1}, {kC, Role::CommandPad}});
  seen.listing.remotes = {listed(kA, "/dev/hidraw1"), listed(kB, "/dev/hidraw2"), listed(kC, "/dev/hidraw3"),
                          listed(kD, "/dev/hidraw4")};
  const auto steps = missed_steps(seen);
  REQUIRE(steps.size() == 1);
  CHECK(steps[0].line == std::string(kD) + ": not in the \"remotes\" of rig.json, so fire app --live leaves it alone: the pad "
                                           "there is " + kC + "; switch this one off, or put its address in place of the "
                                           "remote it replaces (docs/hardware.md section 7)");
}

TEST_CASE("a low battery is read from a fake remote's status report, its own flag") {
  // The listing waits in real time, as it does for hidapi.
  FakeBus bus(system_clock());
  bus.add_remote({.address = kA, .product = kProductRemote, .rate_hz = 100, .phase_ns = 0, .battery = 0x1E});  // flagged
  bus.add_remote({.address = kB, .product = kProductRemote, .rate_hz = 100, .phase_ns = 0, .battery = 0x20});  // not yet
  const auto listing = list_remotes(bus, {}, 200);
  REQUIRE(listing.ok());
  DevicesSeen seen = with_adapter();
  seen.listing = *listing;
  const auto steps = missed_steps(seen);
  REQUIRE(steps.size() == 1);
  CHECK(steps[0].step == Step::Battery);
  CHECK_THAT(steps[0].line, Catch::StartsWith(std::string("camera0 ") + kA + ": its battery is low (15 %)"));
}
