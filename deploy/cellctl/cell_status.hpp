#pragma once
// What `cellctl status` reports: the resources as DDS shows them (alive, held by which order,
// restarts from the journal) and, from the cell's database, the inventory with the
// conservation of every part type and the orders with their states and reasons.

#include <nlohmann/json.hpp>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/cell_observer.hpp"
#include "services/state/cell_store.hpp"

namespace cellctl {

// {"inventory": {TYPE: {"initial", "in_buffers", "assembled", "on_stations", "in_transit",
// "inspection", "conserved"}}, "orders": [{"order", "state", "reason", "quote", "place" (in the
// queue), "progress", "message" (its twin's last status)}], "resources": [{"id", "kind",
// "alive", "reserved_by", "waiting", "busy", "queued", "refused", "last_refusal", "restarts",
// "stock" (a buffer's, as it says), "position", "dock"}], "state_dir"}. Without a database
// yet, the inventory and the stored orders are empty.
nlohmann::json cell_status(const CellConfig& cell, const CellObserver& observer);
// The process a resource lives in, whose ends and restarts are its own (an arm's: its station's).
std::string process_of(const CellConfig& cell, const std::string& resource);
// The same from a database already open (`store` may be null: none yet).
nlohmann::json cell_status(const CellConfig& cell, const CellObserver& observer, const state::CellStore* store);

}  // namespace cellctl
