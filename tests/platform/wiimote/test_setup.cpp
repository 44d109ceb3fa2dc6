// Everything around the driver that a person meets first: roles in the rig file, `fire devices`'
// listing, and the advice for a remote that cannot be opened.
#include <catch2/catch.hpp>

#include <filesystem>
#include <string>
#include <unistd.h>
#include <utility>
#include <vector>

#include "platform/files.hpp"
#include "platform/wiimote/fake_remote.hpp"
#include "platform/wiimote/listing.hpp"
#include "platform/wiimote/roles.hpp"
#include "platform/wiimote/setup_advice.hpp"
#include "systems/tracking/rig_io.hpp"

using namespace fire;
using namespace fire::wiimote;

namespace {

const char* kRig = R"({
  "format": "fire-rig", "version": 1, "units": "metres, pixels",
  "cameras": [
    {"intrinsics": {"fx": 1300, "fy": 1300, "cx": 512, "cy": 384, "k1": 0, "k2": 0},
     "R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 0]},
    {"intrinsics": {"fx": 1300, "fy": 1300, "cx": 512, "cy": 384, "k1": 0, "k2": 0},
     "R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [-0.5, 0, 0]}],
  "calibration": {"reprojection_rms_px": 0.2, "reprojection_rms_2d_px": 0.3, "wand_length_error_mm": 0.7,
                  "observations_used": 100, "observations_rejected": 0, "iterations": 5},
  "remotes": [{"address": "00:1f:32:aa:bb:01", "role": "camera0"},
              {"address": "001F32AABB02", "role": "camera1"},
              {"address": "00-1F-32-AA-BB-03", "role": "pad"}]
})";

}  // namespace

TEST_CASE("roles by address come from the rig file, which the rig reader still accepts") {
  const auto roles = remotes_from_rig_json(kRig, "rig.json");
  REQUIRE(roles.ok());
  REQUIRE(roles->size() == 3);
  CHECK((*roles)[0].address == "00:1F:32:AA:BB:01");
  CHECK((*roles)[1].address == "00:1F:32:AA:BB:02");
  CHECK((*roles)[2].role == Role::CommandPad);
  CHECK(tracking::rig_from_json(kRig, "rig.json").ok());

  CHECK(remotes_from_rig_json(R"({"format": "fire-rig"})", "r")->empty());
  const auto bad_role = remotes_from_rig_json(R"({"remotes": [{"address": "00:1F:32:AA:BB:01", "role": "left"}]})", "r");
  REQUIRE_FALSE(bad_role.ok());
  CHECK_THAT(bad_role.error(), Catch::Contains("r: remotes[0]: unknown role \"left\""));
  const auto twice = remotes_from_rig_json(
      R"({"remotes": [{"address": "00:1F:32:AA:BB:01", "role": "camera0"}, {"address": "00:1f:32:aa:bb:01", "role": "camera1"}]})", "r");
  REQUIRE_FALSE(twice.ok());
  CHECK_THAT(twice.error(), Catch::Contains("given twice"));
  CHECK_FALSE(remotes_from_rig_json("[1]", "r").ok());
}

TEST_CASE("fire devices' table: none, a ready one with its battery, one that cannot be opened") {
  // The listing waits in real time, as it does for hidapi; so the remotes' radio latency runs on it too.
  FakeBus bus(system_clock());
  SECTION("none") {
    bus.add_other_device({.vendor = kNintendoVendor, .product = 0x0337, .serial = "", .path = "fake:adapter"});
    const auto listing = list_remotes(bus, {});
    REQUIRE(listing.ok());
    CHECK(listing->remotes.empty());
    CHECK(listing->others.size() == 1);
    CHECK(format_listing(*listing).empty());
  }
  SECTION("some") {
    bus.add_remote({.address = "00:1F:32:AA:BB:02", .product = kProductRemotePlus, .rate_hz = 100, .phase_ns = 0, .battery = 0x64});
    bus.add_remote({.address = "00:1F:32:AA:BB:01"});
    bus.deny_open("00:1F:32:AA:BB:01", permission_advice("/dev/hidraw3"));
    const auto roles = remotes_from_rig_json(kRig, "rig.json");
    const auto listing = list_remotes(bus, *roles, 100);
    REQUIRE(listing.ok());
    REQUIRE(listing->remotes.size() == 2);
    const ListedRemote& denied = listing->remotes[0];
    CHECK(denied.state == ListedState::CannotOpen);
    CHECK(denied.role == Role::Camera0);
    const ListedRemote& ready = listing->remotes[1];
    CHECK(ready.state == ListedState::Ready);
    CHECK(ready.role == Role::Camera1);
    REQUIRE(ready.status);
    CHECK(battery_percent(*ready.status) == 50);
    const std::string text = format_listing(*listing);
    CHECK_THAT(text, Catch::StartsWith("address            role      state        battery  product   path\n"
                                       "00:1F:32:AA:BB:01  camera0   cannot open  -        0306      fake:00:1F:32:AA:BB:01\n"
                                       "00:1F:32:AA:BB:02  camera1   ready        50 %     0330"));
    CHECK_THAT(denied.problem, Catch::Contains("fake:00:1F:32:AA:BB:01: permission denied on /dev/hidraw3"));
    CHECK_THAT(denied.problem, Catch::Contains("sudo install -m 644 platform/wiimote/99-fire-wiimote.rules /etc/udev/rules.d/"));
  }
}

TEST_CASE("the shipped udev rule covers both Wii Remote products over Bluetooth") {
  const auto rule = read_text_file(std::string(FIRE_SOURCE_DIR) + "/" + kUdevRule);
  REQUIRE(rule.ok());
  CHECK_THAT(*rule, Catch::Contains("KERNELS==\"0005:057E:0306.*\""));
  CHECK_THAT(*rule, Catch::Contains("KERNELS==\"0005:057E:0330.*\""));
  CHECK_THAT(*rule, Catch::Contains("TAG+=\"uaccess\""));
  CHECK_THAT(*rule, Catch::Contains(udev_install_command()));
}

TEST_CASE("hid-wiimote bound to a remote is found in sysfs, with the commands that hand it to hid-generic") {
  namespace fs = std::filesystem;
  const fs::path root = fs::temp_directory_path() / ("fire-sysfs-" + std::to_string(::getpid()));
  fs::remove_all(root);
  const fs::path hid = root / "devices/platform/bt/0005:057E:0306.0003";
  fs::create_directories(hid);
  fs::create_directories(root / "bus/hid/drivers/wiimote");
  fs::create_directories(root / "class/hidraw/hidraw3");
  fs::create_directories(root / "class/hidraw/hidraw4");
  fs::create_directory_symlink(hid, root / "class/hidraw/hidraw3/device");
  fs::create_directory_symlink(root / "bus/hid/drivers/wiimote", hid / "driver");
  const fs::path free_hid = root / "devices/platform/bt/0005:057E:0330.0004";
  fs::create_directories(free_hid);
  fs::create_directory_symlink(free_hid, root / "class/hidraw/hidraw4/device");

  const auto bound = kernel_binding("/dev/hidraw3", root.string());
  REQUIRE(bound);
  CHECK(bound->hid_id == "0005:057E:0306.0003");
  CHECK(bound->driver == kKernelWiimoteDriver);
  const std::string advice = unbind_advice(*bound);
  CHECK_THAT(advice, Catch::Contains("echo 1 | sudo tee /sys/module/hid/parameters/ignore_special_drivers"));
  CHECK_THAT(advice, Catch::Contains("echo -n 0005:057E:0306.0003 | sudo tee /sys/bus/hid/drivers/wiimote/unbind; "
                                     "echo -n 0005:057E:0306.0003 | sudo tee /sys/bus/hid/drivers/hid-generic/bind"));
  CHECK(advice.find("ignore_special_drivers") < advice.find("/unbind"));
  CHECK_THAT(advice, !Catch::Contains("blacklist"));
  const auto unbound = kernel_binding("/dev/hidraw4", root.string());
  REQUIRE(unbound);
  CHECK(unbound->driver.empty());
  CHECK_FALSE(kernel_binding("/dev/hidraw9", root.string()));
  CHECK_FALSE(kernel_binding("/dev/ttyS0", root.string()));
  fs::remove_all(root);
}

namespace {

namespace fs = std::filesystem;

// A /sys laid out as the kernel lays it out: each HID device under devices/, a link to it in
// bus/hid/devices, its driver a link into bus/hid/drivers, its hidraw node only while a driver made one.
struct FakeSysfs {
  fs::path root = fs::temp_directory_path() / ("fire-fake-sysfs-" + std::to_string(::getpid()));
  FakeSysfs() {
    fs::remove_all(root);
    fs::create_directories(root / "bus/hid/devices");
    fs::create_directories(root / "bus/hid/drivers/wiimote");
    fs::create_directories(root / "bus/hid/drivers/hid-generic");
  }
  ~FakeSysfs() { fs::remove_all(root); }
  void add(const std::string& hid_id, const std::string& name, const std::string& uniq, const std::string& driver,
           const std::string& hidraw) const {
    const fs::path dev = root / "devices/virtual/misc/uhid" / hid_id;
    fs::create_directories(dev);
    fs::create_directory_symlink(dev, root / "bus/hid/devices" / hid_id);
    REQUIRE(write_file_atomic((dev / "uevent").string(), "DRIVER=" + driver + "\nHID_ID=0005:0000057E:00000306\nHID_NAME=" + name +
                                                            "\nHID_PHYS=aa:bb\nHID_UNIQ=" + uniq + "\nMODALIAS=hid:b0005\n"));
    if (!driver.empty()) fs::create_directory_symlink(root / "bus/hid/drivers" / driver, dev / "driver");
    if (!hidraw.empty()) fs::create_directories(dev / "hidraw" / hidraw);
  }
  // An adapter as class/bluetooth links it, with its rfkill switch ("0" or "1"), and one of its links.
  void adapter(const std::string& name, const std::string& soft, const std::string& hard) const {
    const fs::path dev = root / "devices/pci0000:00/usb1/1-1/1-1:1.0/bluetooth" / name;
    fs::create_directories(dev / "rfkill3");
    fs::create_directories(dev / (name + ":11"));
    fs::create_directories(root / "class/bluetooth");
    fs::create_directory_symlink(dev, root / "class/bluetooth" / name);
    fs::create_directory_symlink(dev / (name + ":11"), root / "class/bluetooth" / (name + ":11"));
    REQUIRE(write_file_atomic((dev / "rfkill3/soft").string(), soft + "\n"));
    REQUIRE(write_file_atomic((dev / "rfkill3/hard").string(), hard + "\n"));
  }
  void parameter(const std::string& value) const {
    fs::create_directories(root / "module/hid/parameters");
    REQUIRE(write_file_atomic((root / "module/hid/parameters/ignore_special_drivers").string(), value + "\n"));
  }
  SysfsRemote only() const {
    const SysfsSetup setup = scan_sysfs(root.string());
    REQUIRE(setup.remotes.size() == 1);
    return setup.remotes[0];
  }
};

constexpr const char* kId = "0005:057E:0306.0003";
constexpr const char* kSetParameter = "echo 1 | sudo tee /sys/module/hid/parameters/ignore_special_drivers";
constexpr const char* kBindGeneric = "echo -n 0005:057E:0306.0003 | sudo tee /sys/bus/hid/drivers/hid-generic/bind";
constexpr const char* kUnbindWiimote = "echo -n 0005:057E:0306.0003 | sudo tee /sys/bus/hid/drivers/wiimote/unbind";

}  // namespace

TEST_CASE("sysfs says, for each Wii Remote, which step stands between it and FIRE") {
  FakeSysfs sys;
  SECTION("no driver bound, special drivers honoured: set the parameter, then bind hid-generic") {
    sys.parameter("N");
    sys.add(kId, "Nintendo RVL-CNT-01", "00:1f:32:aa:bb:01", "", "");
    const SysfsRemote r = sys.only();
    CHECK(r.verdict == SetupVerdict::NoNode);
    CHECK(r.address == "00:1F:32:AA:BB:01");
    CHECK(r.name == "Nintendo RVL-CNT-01");
    CHECK(r.driver.empty());
    CHECK(r.hidraw.empty());
    CHECK_THAT(r.message, Catch::StartsWith("0005:057E:0306.0003 (00:1F:32:AA:BB:01): no HID driver is bound"));
    CHECK_THAT(r.message, Catch::Contains("blacklisting hid_wiimote"));
    CHECK_THAT(r.message, Catch::Contains(std::string("1. set hid.ignore_special_drivers: ") + kSetParameter));
    CHECK_THAT(r.message, Catch::Contains("hid.ignore_special_drivers=1 on the kernel command line"));
    CHECK_THAT(r.message, Catch::Contains(std::string("2. ") + kBindGeneric));
    CHECK_THAT(r.message, Catch::Contains("bluetoothctl disconnect 00:1F:32:AA:BB:01"));
    CHECK_THAT(r.message, !Catch::Contains("unbind"));
  }
  SECTION("no driver bound, special drivers ignored: bind hid-generic only") {
    sys.parameter("Y");
    sys.add(kId, "Nintendo RVL-CNT-01", "00:1f:32:aa:bb:01", "", "");
    const SysfsRemote r = sys.only();
    CHECK(r.verdict == SetupVerdict::NoNode);
    CHECK_THAT(r.message, Catch::Contains(std::string("no hidraw node for FIRE to open: ") + kBindGeneric));
    CHECK_THAT(r.message, !Catch::Contains(kSetParameter));
  }
  SECTION("held by hid-wiimote, special drivers honoured: set the parameter, then rebind") {
    sys.parameter("0");
    sys.add(kId, "Nintendo RVL-CNT-01", "00:1f:32:aa:bb:01", "wiimote", "hidraw3");
    const SysfsRemote r = sys.only();
    CHECK(r.verdict == SetupVerdict::KernelDriver);
    CHECK(r.driver == kKernelWiimoteDriver);
    CHECK(r.hidraw == "hidraw3");
    CHECK_THAT(r.message, Catch::StartsWith("0005:057E:0306.0003 (00:1F:32:AA:BB:01): held by the kernel's hid-wiimote driver"));
    CHECK_THAT(r.message, Catch::Contains(std::string("1. set hid.ignore_special_drivers: ") + kSetParameter));
    CHECK_THAT(r.message, Catch::Contains(std::string("2. ") + kUnbindWiimote + "; " + kBindGeneric));
    CHECK_THAT(r.message, Catch::EndsWith(" (docs/hardware.md section 6; details: docs/wiimote.md section 2)"));
  }
  SECTION("held by hid-wiimote, special drivers ignored: it was bound first, so only rebind or reconnect") {
    sys.parameter("1");
    sys.add(kId, "Nintendo RVL-CNT-01", "00:1f:32:aa:bb:01", "wiimote", "hidraw3");
    const SysfsRemote r = sys.only();
    CHECK(r.verdict == SetupVerdict::KernelDriver);
    CHECK_THAT(r.message, Catch::Contains("although hid.ignore_special_drivers is set"));
    CHECK_THAT(r.message, Catch::Contains(std::string(kUnbindWiimote) + "; " + kBindGeneric));
    CHECK_THAT(r.message, Catch::Contains("or reconnect it: bluetoothctl disconnect 00:1F:32:AA:BB:01"));
    CHECK_THAT(r.message, !Catch::Contains(kSetParameter));
  }
  SECTION("held by hid-wiimote, the parameter unreadable (only root may read it): check it, then set it") {
    sys.add(kId, "Nintendo RVL-CNT-01-TR", "", "wiimote", "hidraw3");
    const SysfsRemote r = sys.only();
    CHECK(r.verdict == SetupVerdict::KernelDriver);
    CHECK_THAT(r.message, Catch::StartsWith("0005:057E:0306.0003: held by"));
    CHECK_THAT(r.message, Catch::Contains("1. unless sudo cat /sys/module/hid/parameters/ignore_special_drivers says 1, set it: "));
    CHECK_THAT(r.message, Catch::Contains("or reconnect it: switch the remote off and on"));
  }
  SECTION("held by hid-generic with a hidraw node: ready") {
    sys.parameter("Y");
    sys.add(kId, "Nintendo RVL-CNT-01", "00:1f:32:aa:bb:01", "hid-generic", "hidraw5");
    const SysfsRemote r = sys.only();
    CHECK(r.verdict == SetupVerdict::Ready);
    CHECK(r.message == "0005:057E:0306.0003 (00:1F:32:AA:BB:01): ready: hid-generic holds it, /dev/hidraw5");
  }
  SECTION("held by hid-generic without a hidraw node: the hidraw module is missing") {
    sys.parameter("Y");
    sys.add(kId, "Nintendo RVL-CNT-01", "00:1f:32:aa:bb:01", "hid-generic", "");
    const SysfsRemote r = sys.only();
    CHECK(r.verdict == SetupVerdict::NoNode);
    CHECK_THAT(r.message, Catch::Contains("made no hidraw node: sudo modprobe hidraw"));
  }
  SECTION("a Wii U Pro Controller shares the ids: listed, left alone") {
    sys.parameter("N");
    sys.add("0005:057E:0330.0007", "Nintendo RVL-CNT-01-UC", "00:1f:32:aa:bb:07", "wiimote", "hidraw7");
    const SysfsRemote r = sys.only();
    CHECK(r.verdict == SetupVerdict::NotARemote);
    CHECK_THAT(r.message, Catch::Contains("0005:057E:0330.0007 (00:1F:32:AA:BB:07): \"Nintendo RVL-CNT-01-UC\""));
    CHECK_THAT(r.message, Catch::Contains("left alone"));
    CHECK_THAT(r.message, !Catch::Contains("bind"));
    CHECK_THAT(r.message, !Catch::Contains("ignore_special_drivers"));
  }
  SECTION("other HID devices are not listed; remotes come by hid id") {
    sys.add("0003:046D:C52B.0001", "Logitech USB Receiver", "", "hid-generic", "hidraw0");
    sys.add("0005:057E:0330.0009", "Nintendo RVL-CNT-01-TR", "00:1f:32:aa:bb:09", "hid-generic", "hidraw9");
    sys.add(kId, "Nintendo RVL-CNT-01", "00:1f:32:aa:bb:01", "", "");
    const SysfsSetup setup = scan_sysfs(sys.root.string());
    CHECK_FALSE(setup.ignore_special_drivers.has_value());
    CHECK(setup.devices_dir == (sys.root / "bus/hid/devices").string());
    REQUIRE(setup.remotes.size() == 2);
    CHECK(setup.remotes[0].hid_id == kId);
    CHECK(setup.remotes[1].verdict == SetupVerdict::Ready);
  }
}

TEST_CASE("hid's ignore_special_drivers reads as the kernel writes it, and as a bool parameter would") {
  FakeSysfs sys;
  const std::vector<std::pair<std::string, bool>> values = {{"1", true}, {"0", false}, {"Y", true}, {"N", false}};
  for (const auto& [text, set] : values) {
    sys.parameter(text);
    CHECK(scan_sysfs(sys.root.string()).ignore_special_drivers == set);
  }
  sys.parameter("maybe");
  CHECK_FALSE(scan_sysfs(sys.root.string()).ignore_special_drivers.has_value());
  CHECK_FALSE(scan_sysfs((sys.root / "nowhere").string()).ignore_special_drivers.has_value());
  CHECK(scan_sysfs((sys.root / "nowhere").string()).remotes.empty());
}

TEST_CASE("the Bluetooth adapters in class/bluetooth, switched off when rfkill blocks them, and not their links") {
  FakeSysfs sys;
  CHECK(scan_sysfs(sys.root.string()).adapters.empty());
  sys.adapter("hci0", "1", "0");
  sys.adapter("hci1", "0", "0");
  sys.adapter("hci2", "0", "1");
  const SysfsSetup setup = scan_sysfs(sys.root.string());
  CHECK(setup.bluetooth_dir == (sys.root / "class/bluetooth").string());
  REQUIRE(setup.adapters.size() == 3);
  CHECK(setup.adapters[0].name == "hci0");
  CHECK(setup.adapters[0].blocked);
  CHECK(setup.adapters[1].name == "hci1");
  CHECK_FALSE(setup.adapters[1].blocked);
  CHECK(setup.adapters[2].blocked);
}
