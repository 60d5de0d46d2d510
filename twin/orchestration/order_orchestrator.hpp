#pragma once
// One order's orchestration (the paper's Fig. 5 after planning), as an IEC 61499 basic block
// driven by events, never waiting on a call:
//
//   NEGOTIATING  calls for proposals for every operation the order needs (the station to
//                host it, the arm, the mobile robot, a buffer per part type), awards the
//                first proposer, waits for confirmations; calls again every tick until
//                `wait_timeout`, then fails with what nobody offered.
//   VIRTUAL      virtual assembly in cell-sim: each part spawned where its trajectory
//                starts, gripped, moved, released, the arm backs out, the part connected.
//                A collision cell-sim reports is answered with the next trajectory the
//                planner had for that part; none left: back to sequence planning from the
//                parts assembled so far, with that part barred from coming next (another
//                order); no order left fails the order.
//   PHYSICAL     the virtual parts removed; every part spawned at its buffer's dock; the
//                mobile robot's queue filled with fetches in planned order; for each step the
//                arm waits for that part's delivery, grips it at the station's dock, carries
//                it up and over to its trajectory, inserts, releases, backs out, connects.
//   CLEANUP      the order's bodies leave cell-sim (the product leaves the station), then
//   DONE/FAILED  reservations released; FINISHED.
//
// Every step is an action (a cell-sim request, a command, or waiting for a delivery) in a
// queue; the next starts when the one before is answered.
//
//   inputs: START, TICK, CAPABILITY (resource_id, dock, position), RESOURCE_GONE
//           (resource_id), PROPOSAL (call_id, resource_id), AWARD_REPLY (call_id,
//           resource_id, confirmed, reason), COMMAND_EVENT (command_id, order_id, state,
//           reason), SIM_REPLY (request_id, ok, error, collided, ...)
//   outputs: CFP, AWARD, RELEASE, COMMAND, CANCEL (fetches not delivered when the order
//            fails), SIM (the topics' fields), STATUS (state, message,
//            progress), FINDING (kind, message, part), FINISHED (complete, error)

#include <chrono>
#include <deque>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "services/node/sim_requests.hpp"
#include "services/runtime/basic_block.hpp"
#include "twin/planning/assembly_planner.hpp"

namespace twin {

struct OrderSettings {
  std::string order_id;
  std::chrono::milliseconds wait_timeout{30000};  // for resources to offer what the order needs
  std::chrono::milliseconds cleanup_timeout{5000};
  double award_lease_s = 10;
};

class OrderOrchestrator : public fb::BasicBlock {
 public:
  OrderOrchestrator(std::string name, const LoadedProduct& product, const Plan& plan, OrderSettings settings);

  // The plan as virtual assembly left it: the sequence (replanned if cell-sim made it go
  // back), each step done so far with the trajectory cell-sim validated.
  const Plan& plan() const { return plan_; }
  const std::string& error() const { return error_; }

 private:
  struct Action {
    enum Kind { sim, command, send_only, await_delivery } kind;
    fb::Data data;
    bool retry_on_collision = false;  // a move of a candidate trajectory in virtual assembly
  };
  struct Need {
    std::string operation, part_type, awarded, pending;
  };

  // Negotiation.
  void call_for_proposals();
  bool negotiated() const;
  // Enters RUNNING with virtual assembly once every need is awarded; false until then.
  bool start_when_negotiated();
  const std::string& awarded(const std::string& operation, const std::string& part_type = "") const;
  // Scripts.
  void plan_virtual_step();
  void add_candidate(std::size_t step, std::size_t candidate);
  void plan_physical();
  void plan_cleanup();
  void add_trajectory_moves(const std::string& body, const std::vector<Pose>& holding_pads,
                            const std::vector<Pose>& retreat_pads, bool retry);
  fb::Data command(const std::string& resource, const std::string& operation, const std::string& part = "");
  // Running them.
  void next_action();
  void action_done();
  void on_collision(const std::string& reason);
  // No trajectory of the current step's part works in cell-sim: plan the rest again.
  void back_to_sequence_planning();
  void fail(const std::string& reason);
  void finish();
  void status(const std::string& state, const std::string& message, double progress);
  std::vector<Trajectory> candidates(std::size_t step) const;
  Pose at_station(const Pose& pose) const;
  fb::Numbers pose_numbers(const std::vector<Pose>& poses) const;
  std::string virtual_body(PartIndex part) const;
  std::string physical_body(PartIndex part) const;

  const LoadedProduct& product_;
  Plan plan_;
  AssemblyScene scene_;  // for the gripper's pad size per part and push
  OrderSettings settings_;
  fb::SimRequests sim_;
  std::vector<Need> needs_;
  std::map<std::string, fb::Numbers> docks_, positions_;
  std::chrono::steady_clock::time_point phase_started_;
  std::deque<Action> actions_;
  bool action_running_ = false;
  std::string awaited_id_;
  std::size_t command_count_ = 0;
  std::size_t step_ = 0, candidate_ = 0;
  std::string phase_;  // "virtual", "physical", "cleanup"
  std::map<std::size_t, std::set<PartIndex>> barred_;  // step -> parts cell-sim refused there
  std::set<std::string> delivered_, spawned_;
  std::map<std::string, PartIndex> fetch_of_;
  std::string error_;
};

}  // namespace twin
