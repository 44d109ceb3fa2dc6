#include "platform/wiimote/roles.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>

namespace fire::wiimote {

Result<std::vector<RemoteAssignment>> remotes_from_rig_json(std::string_view text, const std::string& source) {
  using R = Result<std::vector<RemoteAssignment>>;
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) return R::failure(source + ": not a JSON object");
  std::vector<RemoteAssignment> out;
  if (!j.contains("remotes")) return out;
  const nlohmann::json& list = j.at("remotes");
  if (!list.is_array()) return R::failure(source + ": \"remotes\" must be an array");
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string where = source + ": remotes[" + std::to_string(i) + "]";
    const nlohmann::json& e = list.at(i);
    if (!e.is_object() || !e.contains("address") || !e.at("address").is_string() || !e.contains("role") ||
        !e.at("role").is_string())
      return R::failure(where + ": expected {\"address\": \"00:1F:32:AA:BB:CC\", \"role\": \"camera0|camera1|pad\"}");
    const std::optional<Role> role = parse_role(e.at("role").get<std::string>());
    if (!role) return R::failure(where + ": unknown role \"" + e.at("role").get<std::string>() + "\" (camera0, camera1 or pad)");
    RemoteAssignment a{.address = normalize_address(e.at("address").get<std::string>()), .role = *role};
    for (const RemoteAssignment& b : out) {
      if (b.address == a.address) return R::failure(where + ": address " + a.address + " given twice");
      if (b.role == a.role) return R::failure(where + ": role " + std::string(role_name(a.role)) + " given twice");
    }
    out.push_back(std::move(a));
  }
  return out;
}

std::optional<Role> role_of(const std::string& address, const std::vector<RemoteAssignment>& assigned,
                            const std::vector<DeviceInfo>& found) {
  const std::string a = normalize_address(address);
  if (!assigned.empty()) {
    for (const RemoteAssignment& r : assigned)
      if (r.address == a) return r.role;
    return std::nullopt;
  }
  std::vector<std::string> remotes;
  for (const DeviceInfo& d : found)
    if (is_wii_remote(d)) remotes.push_back(normalize_address(d.serial));
  std::sort(remotes.begin(), remotes.end());
  remotes.erase(std::unique(remotes.begin(), remotes.end()), remotes.end());
  const auto it = std::find(remotes.begin(), remotes.end(), a);
  if (it == remotes.end()) return std::nullopt;
  const auto rank = it - remotes.begin();
  if (rank > 2) return std::nullopt;
  return static_cast<Role>(rank);
}

}  // namespace fire::wiimote
