#pragma once
// The operator takes a resource of the cell out of service and back (`cellctl service`, the
// dashboard). The ask is stored (state::CellStore::set_out_of_service); cellctl up carries it
// to the resource in the cell's roster, and the resource then takes no new work: calls for it
// are refused with the reason, while the orders that hold it, wait for it or gave it work are
// served (services/blocks/contractor.hpp).

#include <map>
#include <string>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/order_intake.hpp"
#include "services/state/cell_store.hpp"

namespace cellctl {

// `reason` "" puts it back into service. Refused (400, 404): a resource the deployment file
// does not name, a reason longer than 500 characters or holding control characters.
ActionAnswer set_resource_service(const CellConfig& cell, state::CellStore& store, const std::string& resource,
                                  const std::string& reason, const std::string& who);

// What the store says is out of service, for the roster: resource -> "REASON (WHO)".
std::map<std::string, std::string> out_of_service_in(const state::CellStore& store);

}  // namespace cellctl
