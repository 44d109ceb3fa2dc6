#pragma once
// Which remote is which. Remotes enumerate in no fixed order, so each is known by its Bluetooth
// address; the rig file (systems/tracking/README.md) stores the address of each role in an
// optional member that the rig reader leaves alone:
//   "remotes": [{"address": "00:1F:32:AA:BB:01", "role": "camera0"},
//               {"address": "00:1F:32:AA:BB:02", "role": "camera1"},
//               {"address": "00:1F:32:AA:BB:03", "role": "pad"}]
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/common.hpp"
#include "platform/wiimote/device.hpp"
#include "platform/wiimote/remote_machine.hpp"

namespace fire::wiimote {

struct RemoteAssignment {
  std::string address;  // normalized (normalize_address)
  Role role = Role::Camera0;
};

// The "remotes" member of a rig file; none when the file has no such member. Each role and each
// address at most once; errors name the source and the entry.
Result<std::vector<RemoteAssignment>> remotes_from_rig_json(std::string_view text, const std::string& source);

// The role of a found remote: from `assigned` when given; with no assignment at all, by the
// order of the addresses of the Wii Remotes found (camera 0, camera 1, then the pad), so a first
// session works before any rig file exists. nullopt: the remote has no role and is left alone.
std::optional<Role> role_of(const std::string& address, const std::vector<RemoteAssignment>& assigned,
                            const std::vector<DeviceInfo>& found);

}  // namespace fire::wiimote
