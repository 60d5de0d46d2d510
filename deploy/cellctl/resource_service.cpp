#include "deploy/cellctl/resource_service.hpp"

#include <algorithm>

namespace cellctl {

constexpr std::size_t kMaxReason = 500;

ActionAnswer set_resource_service(const CellConfig& cell, state::CellStore& store, const std::string& resource,
                                  const std::string& reason, const std::string& who) {
  const auto ids = cell.resource_ids();
  if (std::find(ids.begin(), ids.end(), resource) == ids.end()) {
    return {404, "the cell has no resource '" + resource.substr(0, 64) + "' (" + cell.file.string() + ")"};
  }
  if (reason.size() > kMaxReason) return {400, "the reason is longer than " + std::to_string(kMaxReason) + " characters"};
  if (std::any_of(reason.begin(), reason.end(), [](unsigned char c) { return c < 0x20 || c == 0x7f; })) {
    return {400, "the reason holds a control character"};
  }
  const bool out = !reason.empty();
  store.set_out_of_service(resource, reason, who);
  store.journal(who, out ? "out of service" : "in service", "", resource + (out ? ": " + reason : ""));
  return {200, resource + (out ? " is out of service: it takes no new work (what it has taken on, it finishes)"
                               : " is back in service")};
}

std::map<std::string, std::string> out_of_service_in(const state::CellStore& store) {
  std::map<std::string, std::string> out;
  for (const auto& [resource, r] : store.out_of_service()) out[resource] = r.reason + " (" + r.by + ")";
  return out;
}

}  // namespace cellctl
