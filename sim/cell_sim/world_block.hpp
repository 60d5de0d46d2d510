#pragma once
// cell-sim's function block: requests change the world at once and are answered at once
// (a "ping" changes nothing and is answered too; a spawn of a body its requester has
// already replaces it: a resource that restarted spawns its bodies again);
// a move in the physical cell is answered when the sim clock reaches its end (or its first
// collision), a move in a virtual scene at once (virtual assembly is a check). TICK
// (from the process's loop) advances the clock and publishes what is due.
//
//   inputs                          outputs
//   REQUEST (SimRequest fields)     REPLY (SimReply fields)
//   TICK                            CLOCK (sim_time, real_time_factor), every clock_period
//                                   REFUSED (refused: how many so far, last_refusal: whose
//                                   request and why), for the cell's status
//   ORDER_ENDED (order_id): the bodies that order spawned leave the world (a twin that died
//   leaves nothing behind for the next order)
//   HIRED (resource_id, order_id): the resource confirmed an award to the order, so it may
//   move the order's parts (RequestPolicy)
// A request that is malformed or not allowed is answered ok = false with the reason, and
// changes nothing. One of a resource of the cell (a requester with bodies of its own)
// refused for an order whose hire of that resource has not come yet waits for it (at most hire_wait of wall time, at most kMaxHeld of them): the hire comes on
// another topic, and a sample of it that was lost is sent again only at the next heartbeat
// (60 orders at once on 2 cores: a robot's fetch overtook its hire by 1.5 s).

#include <chrono>
#include <map>
#include <vector>

#include "services/runtime/function_block.hpp"
#include "sim/cell_sim/request_policy.hpp"
#include "sim/world/sim_world.hpp"

namespace sim {

class WorldBlock : public fb::FunctionBlock {
 public:
  WorldBlock(std::string name, double real_time_factor, fb::CellBounds bounds = {}, double clock_period_s = 0.05,
             std::chrono::milliseconds hire_wait = std::chrono::seconds(5));
  static constexpr std::size_t kMaxHeld = 256;

  double now() const;  // sim s
  const SimWorld& world() const { return world_; }
  void receive(const fb::Event& event) override;

 private:
  void handle(const fb::Data& request, bool may_wait = true);
  void publish_due();

  struct Held {
    std::chrono::steady_clock::time_point until;
    fb::Data request;
  };

  SimWorld world_;
  double factor_;
  std::chrono::duration<double> clock_period_;
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_clock_{};
  std::multimap<double, fb::Data> pending_;  // replies by the sim time they are due
  std::chrono::milliseconds hire_wait_;
  std::vector<Held> held_;  // requests waiting for a hire, in arrival order
  RequestPolicy policy_;
  std::size_t refused_ = 0;
};

}  // namespace sim
