// Everything around the driver that a person meets first: roles in the rig file, `fire devices`'
// listing, and the advice for a remote that cannot be opened.
#include <catch2/catch.hpp>

#include <filesystem>
#include <unistd.h>

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

TEST_CASE("fire devices' listing: none, a ready one with its battery, one that cannot be opened") {
  ManualClock clock;
  FakeBus bus(clock.clock());
  SECTION("none") {
    bus.add_other_device({.vendor = kNintendoVendor, .product = 0x0337, .serial = "", .path = "fake:adapter"});
    const auto listing = list_remotes(bus, {});
    REQUIRE(listing.ok());
    CHECK(listing->remotes.empty());
    CHECK(listing->others.size() == 1);
    CHECK_THAT(format_listing(*listing), Catch::StartsWith("no Wii Remote found"));
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
    CHECK_THAT(text, Catch::Contains("00:1F:32:AA:BB:02  camera1   ready        50 %     0330"));
    CHECK_THAT(text, Catch::Contains("00:1F:32:AA:BB:01: fake:00:1F:32:AA:BB:01: permission denied on /dev/hidraw3"));
    CHECK_THAT(text, Catch::Contains("sudo install -m 644 platform/wiimote/99-fire-wiimote.rules /etc/udev/rules.d/"));
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

TEST_CASE("hid-wiimote bound to a remote is found in sysfs, with the commands that unbind it") {
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
  CHECK_THAT(advice, Catch::Contains("echo -n 0005:057E:0306.0003 | sudo tee /sys/bus/hid/drivers/wiimote/unbind"));
  CHECK_THAT(advice, Catch::Contains("blacklist hid_wiimote"));
  const auto unbound = kernel_binding("/dev/hidraw4", root.string());
  REQUIRE(unbound);
  CHECK(unbound->driver.empty());
  CHECK_FALSE(kernel_binding("/dev/hidraw9", root.string()));
  CHECK_FALSE(kernel_binding("/dev/ttyS0", root.string()));
  fs::remove_all(root);
}
