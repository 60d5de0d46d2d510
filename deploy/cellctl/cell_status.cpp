#include "deploy/cellctl/cell_status.hpp"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <set>

#include "deploy/cellctl/order_desk.hpp"
#include "services/state/cell_store.hpp"

namespace cellctl {
namespace {

// The process a resource lives in, whose restarts are its restarts (an arm's is its station's).
std::string process_of(const CellConfig& cell, const std::string& resource) {
  for (const auto& s : cell.stations) {
    if (s.arm == resource) return s.id;
  }
  return resource;
}

const char* state_of(cell::OrderState state) {
  static const char* names[] = {"SUBMITTED", "PLANNING", "VIRTUAL_ASSEMBLY", "WAITING", "PHYSICAL_ASSEMBLY", "DONE",
                                "FAILED"};
  return names[state];
}

}  // namespace

nlohmann::json cell_status(const CellConfig& cell, const CellObserver& observer) {
  using nlohmann::json;
  std::optional<state::CellStore> store;
  if (std::filesystem::exists(state::CellStore::file_in(cell.state_folder()))) store.emplace(cell.state_folder());

  json inventory = json::object();
  if (store) {
    for (const auto& [type, c] : store->inventory()) {
      inventory[type] = {{"initial", c.initial},         {"in_buffers", c.in_buffers}, {"assembled", c.assembled},
                         {"on_stations", c.on_stations}, {"in_transit", c.in_transit}, {"inspection", c.inspection},
                         {"conserved", c.initial == c.accounted()}};
    }
  }

  // The stored orders first (they outlive their twins), then those only DDS knows of.
  json orders = json::array();
  std::set<std::string> listed;
  const auto live = observer.orders();
  if (store) {
    const auto stored = store->orders();
    const auto queue = OrderDesk::queue(stored);
    for (const auto& o : stored) {
      json order = {{"order", o.order}, {"state", o.state}, {"reason", o.reason}, {"quote", o.quote}};
      if (const std::size_t place = OrderDesk::place_in(queue, o.order)) order["place"] = place;
      orders.push_back(order);
      listed.insert(o.order);
    }
  }
  for (const auto& [id, s] : live) {
    if (listed.count(id)) continue;
    const bool failed = s.state() == cell::FAILED;
    orders.push_back({{"order", id}, {"state", state_of(s.state())}, {"reason", failed ? s.message().to_string() : ""},
                      {"quote", false}});
  }

  json resources = json::array();
  const auto seen = observer.resources();
  std::set<std::string> ids;
  for (const auto& id : cell.resource_ids()) ids.insert(id);
  for (const auto& [id, r] : seen) ids.insert(id);
  for (const auto& id : ids) {
    const auto it = seen.find(id);
    json stock = json::object();
    if (it != seen.end()) {
      for (const auto& s : it->second.capability.stock()) stock[s.part_type().to_string()] = s.count();
    }
    resources.push_back({{"id", id},
                         {"alive", it != seen.end() && it->second.alive},
                         {"reserved_by", it != seen.end() ? it->second.capability.reserved_by().to_string() : ""},
                         {"restarts", store ? store->count_events(process_of(cell, id), "restarted") : 0},
                         {"stock", stock}});
  }
  return {{"inventory", inventory},
          {"orders", orders},
          {"resources", resources},
          {"state_dir", cell.state_folder().string()}};
}

}  // namespace cellctl
