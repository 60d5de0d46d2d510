#pragma once
// The assembly station: the table that products are built on, a body in cell-sim, and a
// place that one order at a time reserves ("host"). Parts are handed over at its dock.
//
//   INIT -> SIM (spawn the table) -> SIM_REPLY -> READY, or FAILED with cell-sim's reason

#include "services/node/device_block.hpp"
#include "services/node/sim_requests.hpp"

namespace fb {

class StationBlock : public DeviceBlock {
 public:
  // The table's top is level with `position`, its size given as half extents.
  StationBlock(std::string name, std::string resource_id, Numbers position, Numbers table_half_extents);
  const std::string& error() const { return error_; }

 private:
  SimRequests sim_;
  std::string error_;
};

}  // namespace fb
