#pragma once
// What every resource process has around its device block, wired as function blocks on the
// device's resource: the command topic into the device, the command life cycle, command
// events out (stamped with sim time), the contract net (calls, proposals, awards, releases,
// the end of orders) through a Contractor, the capability with its liveliness lease, and
// cell-sim requests and replies when the device moves things.
//
//   cell/commands/<id> --> device.COMMAND (checked, authorised by the contractor's awards)
//     --> lifecycle --> cell/command_events; a refused command, or one the queue has no
//     room for, is answered REJECTED with the reason, and counted in the capability
//   cell/negotiation/* and cell/orders/status --> contractor --> proposals, replies, capability
//   (the holder and the queue of waiting orders), device.AWARDED
//   device.SIM --> cell/sim/requests;  cell/sim/replies --> device.SIM_REPLY
//   device.CAPABILITY --> cell/capabilities (e.g. a buffer's stock changed)
//
// With a state folder, the node keeps in the cell's database the command under way and the
// order that holds the resource. A process that follows one that ended answers the command
// its predecessor left ABORTED, with the reason and what became of a part it held; the hold
// is gone with the process that had it (the journal says whose it was).
//
// A device block is any DeviceBlock; the node adds no product knowledge.

#include <array>
#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "capabilities.h"
#include "services/blocks/command_lifecycle.hpp"
#include "services/blocks/contractor.hpp"
#include "services/dds/participant.hpp"
#include "services/dds/sim_clock.hpp"
#include "services/node/device_block.hpp"
#include "services/runtime/resource.hpp"

namespace services {

struct NodeConfig {
  std::string id;
  std::string kind;  // "station", "arm", "mobile-robot", "buffer"
  std::array<double, 3> position{0, 0, 0};
  std::array<double, 3> dock{0, 0, 0};
  double speed = 0;          // m/s
  double angular_speed = 0;  // rad/s
  double reach = 0;          // m
  std::set<std::string> offers;  // operations it bids for in the contract net ("host", "fetch", ...)
  bool exclusive = true;     // held by one order at a time; others wait in its queue
  double liveliness_lease_s = 5.0;
  fb::CellBounds bounds;     // commands' positions must lie inside
  fb::CommandLifecycle::WhenBusy when_busy = fb::CommandLifecycle::WhenBusy::reject;
  // Its commands come from the resource each names as its destination (a buffer's gives: the
  // robot that takes the part), which writes them in its own partition; under DDS-Security a
  // command that another wrote is dropped.
  bool commanded_by_destination = false;
  // The cell's durable state (services/state): "" keeps everything in memory alone.
  std::string state_dir;
};

class ResourceNode {
 public:
  // `device` must already be on `resource`. `estimate` answers calls for proposals (a bid
  // or a refusal with the reason); `describe` adds to the capability what only the device
  // knows (a stock). A device with an AWARDED input hears of the work it was awarded.
  ResourceNode(fb::Resource& resource, dds::ParticipantPtr participant, NodeConfig config, fb::DeviceBlock& device,
               fb::Contractor::EstimateFn estimate, std::function<void(cell::Capability&)> describe = {});
  ~ResourceNode();

  // Starts listening to the topics; call once everything is wired, before the resource's
  // thread runs. A device that moves things first waits until cell-sim answers a ping
  // (requests and replies both get through); throws std::runtime_error if it does not. It
  // stops waiting when `running` (the process's flag, set false by SIGTERM) turns false: a
  // process told to stop while cell-sim is gone ends at once, not after the wait.
  void start(std::chrono::milliseconds wait_for_sim = std::chrono::seconds(30),
             const std::atomic<bool>* running = nullptr);
  dds::SimClock& clock();
  void publish_capability();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace services
