#include "deploy/cellctl/cell_status.hpp"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <set>

#include "deploy/cellctl/order_desk.hpp"
#include "deploy/cellctl/resource_service.hpp"
#include "services/state/cell_store.hpp"

namespace cellctl {
namespace {

const char* state_of(cell::OrderState state) {
  static const char* names[] = {"SUBMITTED", "PLANNING", "VIRTUAL_ASSEMBLY", "WAITING", "PHYSICAL_ASSEMBLY", "DONE",
                                "FAILED"};
  return names[state];
}

}  // namespace

std::string process_of(const CellConfig& cell, const std::string& resource) {
  for (const auto& s : cell.stations) {
    if (s.arm == resource) return s.id;
  }
  return resource;
}

nlohmann::json cell_status(const CellConfig& cell, const CellObserver& observer) {
  std::optional<state::CellStore> store;
  if (std::filesystem::exists(state::CellStore::file_in(cell.state_folder()))) store.emplace(cell.state_folder());
  return cell_status(cell, observer, store ? &*store : nullptr);
}

nlohmann::json cell_status(const CellConfig& cell, const CellObserver& observer, const state::CellStore* store) {
  using nlohmann::json;

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
      if (const auto it = live.find(o.order); it != live.end()) {
        order["progress"] = it->second.progress();
        order["message"] = it->second.message().to_string();
      }
      orders.push_back(order);
      listed.insert(o.order);
    }
  }
  for (const auto& [id, s] : live) {
    if (listed.count(id)) continue;
    const bool failed = s.state() == cell::FAILED;
    orders.push_back({{"order", id}, {"state", state_of(s.state())}, {"reason", failed ? s.message().to_string() : ""},
                      {"quote", false}, {"progress", s.progress()}, {"message", s.message().to_string()}});
  }

  json resources = json::array();
  const auto seen = observer.resources();
  // What the operator asked, until the resource says so itself (a gone one never does).
  const auto asked_out = store ? out_of_service_in(*store) : std::map<std::string, std::string>{};
  std::set<std::string> ids;
  for (const auto& id : cell.resource_ids()) ids.insert(id);
  for (const auto& [id, r] : seen) ids.insert(id);
  for (const auto& id : ids) {
    const auto it = seen.find(id);
    json resource = {{"id", id},
                     {"alive", it != seen.end() && it->second.alive},
                     {"reserved_by", ""},
                     {"restarts", store ? store->count_events(process_of(cell, id), "restarted") : 0},
                     {"stock", json::object()}};
    if (const auto out = asked_out.find(id); out != asked_out.end()) resource["out_of_service"] = out->second;
    if (it != seen.end()) {
      const cell::Capability& c = it->second.capability;
      for (const auto& s : c.stock()) resource["stock"][s.part_type().to_string()] = s.count();
      json waiting = json::array();
      for (const auto& w : c.waiting()) waiting.push_back(w.to_string());
      const auto xyz = [](const cell::Vec3& v) { return json::array({v.x(), v.y(), v.z()}); };
      resource.update({{"kind", c.kind().to_string()},
                       {"reserved_by", c.reserved_by().to_string()},
                       {"waiting", waiting},
                       {"busy", c.busy()},
                       {"queued", c.queued_commands()},
                       {"refused", c.refused_commands()},
                       {"last_refusal", c.last_refusal().to_string()},
                       {"out_of_service", c.out_of_service().to_string()},
                       {"position", xyz(c.position())},
                       {"dock", xyz(c.dock())}});
    }
    resources.push_back(resource);
  }
  return {{"inventory", inventory},
          {"orders", orders},
          {"resources", resources},
          {"state_dir", cell.state_folder().string()}};
}

}  // namespace cellctl
