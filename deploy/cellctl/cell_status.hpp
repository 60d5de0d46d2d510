#pragma once
// What `cellctl status` reports: the resources as DDS shows them (alive, held by which order,
// restarts from the journal) and, from the cell's database, the inventory with the
// conservation of every part type and the orders with their states and reasons.

#include <nlohmann/json.hpp>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/cell_observer.hpp"

namespace cellctl {

// {"inventory": {TYPE: {"initial", "in_buffers", "assembled", "on_stations", "in_transit",
// "inspection", "conserved"}}, "orders": [{"order", "state", "reason"}], "resources": [{"id",
// "alive", "reserved_by", "restarts", "stock" (a buffer's, as it says)}], "state_dir"}. Without a database yet, the inventory
// and the stored orders are empty.
nlohmann::json cell_status(const CellConfig& cell, const CellObserver& observer);

}  // namespace cellctl
