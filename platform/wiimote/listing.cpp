#include "platform/wiimote/listing.hpp"

#include <algorithm>
#include <cstdio>

namespace fire::wiimote {
namespace {

constexpr int kReadMs = 20;

std::string_view listed_state_name(ListedState s) {
  switch (s) {
    case ListedState::Ready: return "ready";
    case ListedState::NoAnswer: return "no answer";
    case ListedState::CannotOpen: return "cannot open";
  }
  return "?";
}

}  // namespace

Result<Listing> list_remotes(Backend& backend, const std::vector<RemoteAssignment>& assigned, int wait_ms) {
  Result<std::vector<DeviceInfo>> found = backend.enumerate();
  if (!found) return Result<Listing>::failure(found.error());
  Listing out;
  for (const DeviceInfo& info : *found) {
    if (!is_wii_remote(info)) {
      out.others.push_back(info);
      continue;
    }
    ListedRemote r{.info = info, .address = normalize_address(info.serial),
                   .role = role_of(info.serial, assigned, *found), .state = ListedState::Ready, .status = {}, .problem = {}};
    Result<std::unique_ptr<Device>> device = backend.open(info);
    if (!device) {
      r.state = ListedState::CannotOpen;
      r.problem = device.error();
    } else if (const Status asked = (*device)->write(status_request_report()); !asked) {
      r.state = ListedState::CannotOpen;
      r.problem = asked.error;
    } else {
      for (int waited = 0; waited < wait_ms && !r.status; waited += kReadMs) {
        const ReadResult read = (*device)->read(kReadMs);
        if (read.status == ReadStatus::Gone) break;
        if (read.status == ReadStatus::Report) r.status = parse_status(read.report);
      }
      if (!r.status) {
        r.state = ListedState::NoAnswer;
        // The hidapi backend refuses a remote on hid-wiimote at open, so silence here is the remote or the radio.
        r.problem = "no status report in " + std::to_string(wait_ms) +
                    " ms: switch it off and on; if it stays silent, check its batteries and its distance to the "
                    "Bluetooth adapter (docs/hardware.md section 1)";
      }
    }
    out.remotes.push_back(std::move(r));
  }
  std::sort(out.remotes.begin(), out.remotes.end(),
            [](const ListedRemote& a, const ListedRemote& b) { return a.address < b.address; });
  return out;
}

std::string format_listing(const Listing& listing) {
  if (listing.remotes.empty()) return {};
  std::string s;
  char line[256];
  std::snprintf(line, sizeof line, "%-17s  %-8s  %-11s  %-7s  %-8s  %s\n", "address", "role", "state", "battery", "product", "path");
  s += line;
  for (const ListedRemote& r : listing.remotes) {
    const std::string battery =
        r.status ? std::to_string(battery_percent(*r.status)) + " %" + (r.status->battery_low() ? " low" : "") : "-";
    std::snprintf(line, sizeof line, "%-17s  %-8s  %-11s  %-7s  %04x      %s\n", r.address.c_str(),
                  r.role ? std::string(role_name(*r.role)).c_str() : "-", std::string(listed_state_name(r.state)).c_str(),
                  battery.c_str(), r.info.product, r.info.path.c_str());
    s += line;
  }
  return s;
}

}  // namespace fire::wiimote
