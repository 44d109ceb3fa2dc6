#pragma once
// What `fire devices` shows: every Wii Remote on the bus, its role, whether FIRE can use it and
// its battery. Each remote is opened, asked for a status report and closed again.
#include <optional>
#include <string>
#include <vector>

#include "platform/wiimote/device.hpp"
#include "platform/wiimote/roles.hpp"

namespace fire::wiimote {

enum class ListedState : uint8_t { Ready, NoAnswer, CannotOpen };

struct ListedRemote {
  DeviceInfo info;
  std::string address;      // normalized
  std::optional<Role> role;
  ListedState state = ListedState::Ready;
  std::optional<StatusReport> status;
  std::string problem;  // NoAnswer and CannotOpen: what is wrong and how to fix it
};

struct Listing {
  std::vector<ListedRemote> remotes;  // by address
  std::vector<DeviceInfo> others;     // HID devices that are not Wii Remotes
};

// Waits up to wait_ms (real time, through read timeouts) for each remote's status report.
Result<Listing> list_remotes(Backend& backend, const std::vector<RemoteAssignment>& assigned, int wait_ms = 500);

// The table `fire devices` prints, one row per remote (their problems are missed_steps' lines); empty
// when there is none.
std::string format_listing(const Listing& listing);

}  // namespace fire::wiimote
