#pragma once
// The mobile robot: a queue of parts to fetch (the life cycle queues the commands; this block
// runs one at a time). For each: drive to the buffer's dock, ask the buffer for a part of the
// type, drive to the station's dock carrying it; the command succeeds on delivery. It knows
// no products: a part is a body id and a type name; places are docks from capabilities.
//
//   INIT -> SIM (spawn its body at home) -> READY
//   START fetch (part, part_type, source, destination)
//     -> SIM move to the source's dock -> GIVE (a "give" command to the source)
//     -> GIVE_EVENT succeeded -> SIM move to the destination's dock carrying the part -> DONE
//   PLACE (resource_id, dock): where a resource hands parts over
//   AWARDED (sources, station): a batch of fetches it was hired for; it will end there;
//     PREPARE_GIVE (resource_id) for each source: its command writer is made before the first give
//   TICK (wall time, from its node): a give with no final answer in time is sent again
// estimate(): how long a batch would take from where its work taken on so far ends.

#include <chrono>
#include <map>

#include "services/blocks/contractor.hpp"
#include "services/node/device_block.hpp"
#include "services/node/sim_requests.hpp"

namespace fb {

class MobileRobotBlock : public DeviceBlock {
 public:
  // `resend_give_after`: how long a give may go without its final answer before it is sent again.
  MobileRobotBlock(std::string name, std::string resource_id, Numbers home, double speed,
                   std::chrono::milliseconds resend_give_after = std::chrono::seconds(2));

  // Driving to each source and on to the destination, s; a refusal when a place is unknown.
  Contractor::Estimate estimate(const std::vector<std::string>& sources, const std::string& destination) const;

 private:
  void check(const Data& command, SampleCheck& check) const override;
  std::string recover() override;
  void drive_to(const std::string& place, const std::vector<std::string>& carried);
  std::string body() const { return resource_id() + "/base"; }

  SimRequests sim_;
  double speed_;
  std::map<std::string, Numbers> docks_;
  Numbers work_ends_at_;  // where the last batch taken on ends
  Data fetch_;          // the command being executed
  std::string give_id_;
  Data give_;           // the give command for it, sent again until its final answer
  std::chrono::steady_clock::time_point give_sent_at_;
  std::chrono::milliseconds resend_give_after_;
  double distance_ = 0, moving_ = 0;  // so far in this fetch
};

}  // namespace fb
