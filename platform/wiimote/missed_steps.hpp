#pragma once
// What `fire devices` names after its table: each set-up step it can see a person has missed, one line
// each with what to do and the section of docs/hardware.md, in the order the guide takes them. It
// reads what hidapi listed and what sysfs shows, and opens nothing, so tests give it made-up ones.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "platform/wiimote/listing.hpp"
#include "platform/wiimote/roles.hpp"
#include "platform/wiimote/setup_advice.hpp"

namespace fire::wiimote {

// The guide's order: pair and connect (section 5), hand the remotes to hid-generic and install the
// udev rule (section 6), then a remote that still will not open or answer, fresh batteries (section 1,
// checked after the set-up as its checklist does), the pad's role in the rig (section 7).
enum class Step : uint8_t { Connect, KernelDriver, Permissions, Answer, Battery, Role };

struct MissedStep {
  Step step = Step::Connect;
  std::string line;  // who, what is missing, what to do, ending with the guide's section
};

struct DevicesSeen {
  Listing listing;   // hidapi's remotes; none under the --sys-root test hook
  SysfsSetup sysfs;  // scan_sysfs
  std::string dev_root;  // where sysfs's hidraw nodes lie ("/dev"); empty: a remote hidapi did not list is not checked
  std::function<bool(const std::string&)> denied;  // the user may not open this node (permission_denied)
  std::vector<RemoteAssignment> assigned;           // the rig's "remotes"; empty: roles by address order
  std::string rig_path;                             // names the rig in messages; empty: none was given
};

// Sorted by step; within a step by address. A remote's battery counts as low when its status report
// sets the low-battery flag (the remote's own judgement, as `fire aim` reads it).
std::vector<MissedStep> missed_steps(const DevicesSeen& seen);

// A remote is there but cannot be used: `fire devices` exits 1. The other steps do not stop a session.
inline bool cannot_use(Step s) { return s == Step::KernelDriver || s == Step::Permissions || s == Step::Answer; }

}  // namespace fire::wiimote
