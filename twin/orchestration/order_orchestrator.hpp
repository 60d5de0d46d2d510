#pragma once
// One order's orchestration (the paper's Fig. 5 after planning), as an IEC 61499 basic block
// driven by events, never waiting on a call. Its execution control chart:
//
//   IDLE -START-> WAITING_CELL   until cell-sim answers a ping and a station of the cell is
//                known (bounded by `wait`)
//   VIRTUAL      virtual assembly in cell-sim, in the order's own virtual scene (it meets
//                the cell's fixtures and nothing of other orders, so many orders do this at
//                once and hold no resource): each part spawned where its trajectory starts,
//                the arm's gripper spawned at the planned grasp, moved, the gripper backs
//                out, the part becomes static. A collision is answered with the next
//                trajectory the planner had for that part; none left: back to sequence
//                planning from the parts assembled so far, with that part barred from coming
//                next; no order left fails the order.
//   BOOKING      a call for a station ("host", with how long physical assembly will hold it);
//                the best bid wins (the Negotiator block does the contract net)
//   QUEUED       the station confirmed a place in its queue: the order holds nothing and
//                waits as long as the queue lasts ("waiting for station-1: 3 orders ahead");
//                it moves to another station whose queue became shorter by two or more (or
//                free); a station that disappears is booked again elsewhere
//   HIRING       the station is held: calls for its arm, for a buffer per part type (with
//                the count) and then for a mobile robot for the batch of fetches
//   PHYSICAL     every part spawned at its buffer's dock; the hired robot's fetches in
//                planned order; for each step the arm waits for that part's delivery, grips
//                it at the station's dock, carries it up and over to its trajectory,
//                inserts, releases, backs out, connects. A subassembly's parts are built so
//                on the station beside the product (its `aside`); the step inserting it
//                makes them movable, grips its base with the others carried, lifts it up
//                and over to its trajectory, inserts, releases, backs out, connects them all.
//                Virtual assembly does the same in the order's scene.
//   CLEANUP      the order's bodies leave cell-sim (the product leaves the station), then
//   ENDED        everything released; FINISHED
// An order for a quote (OrderSettings::quote_only) goes from VIRTUAL to
//   QUOTING      calls for quotes (the Negotiator's ASK: bids, nothing awarded): a station,
//                a buffer per part type, then a mobile robot for the batch; once the
//                station's arm has said its speed, QUOTE: the physical script at the best
//                bids' station, with their robot and buffers, run against the resources'
//                models after their queues (execution_model.hpp), then ENDED; FINISHED. A
//                call nobody bids on fails the order with every refusal's reason.
// A failure anywhere cancels undelivered fetches and goes through CLEANUP to ENDED.
//
// Every change of state is a transition of the chart (its states: Phase). Where an action
// finds the way on, it raises an internal event, which the chart takes next:
//   WAITING_CELL  -CELL_READY->     VIRTUAL    cell-sim answered and a station is known
//   VIRTUAL       -VIRTUAL_DONE->   BOOKING, or QUOTING for a quote
//   BOOKING       -WAITS (ahead)->  QUEUED     the station confirmed a place in its queue
//   BOOKING, QUEUED -STATION_OURS-> HIRING
//   QUEUED        -REBOOK (only)->  BOOKING    a shorter queue elsewhere, or its station gone
//   HIRING        -HIRED->          PHYSICAL   arm held, robot and buffers awarded, places known
//   QUOTING       -PRICED->         ENDED      the quote (QUOTE), FINISHED
//   PHYSICAL      -PHYSICAL_DONE->  CLEANUP
//   any but CLEANUP and ENDED -FAILED-> CLEANUP;  PHYSICAL -TAKE_UP-> ENDED (FINISHED, take_up)
//   any but IDLE, CLEANUP and ENDED -STOP (reason)-> a failure with that reason (the operator
//                cancelled the order), so -FAILED-> CLEANUP
//   CLEANUP       -CLEANED->        ENDED      the bodies removed, or the cleanup's time out
//
// No hold-and-wait: while it waits for a station the order holds nothing; once it holds a
// station, everything else it needs is shared (robots, buffers) or belongs to that station
// (its arm), so every wait is bounded.
//
//   inputs: START, TICK, STOP (reason), CAPABILITY (resource_id, kind, position, dock, speed, angular_speed,
//           reserved_by, waiting), RESOURCE_GONE (resource_id), AWARDED (call_id,
//           resource_id, ahead), QUOTED (call_id, resource_id, earliest_start, duration, bid_time),
//           UNAVAILABLE (call_id, reason), COMMAND_EVENT (command_id,
//           order_id, state, reason, sim_time), SIM_REPLY (request_id, ok, error, collided, ...)
//   outputs: CALL and ASK (to the Negotiator), QUOTE (station, robot, wait: s until
//            the station is the order's, makespan: s until the last step is done, robot_s: s
//            the robot drives for it), PREPARE (resource_id: an arm or robot awarded, that
//            commands will go to), RELEASE, COMMAND, CANCEL (fetches not delivered when
//            the order fails), SIM (the topics' fields), STATUS (state, message, progress),
//            FINDING (kind, message, part), PLACED (part: the bodies released in place,
//            aside: the subassembly they were built into aside, "" in the product; the
//            arm's release recorded it in the cell's state already: progress only),
//            FINISHED (complete, error, take_up: ended for the next twin to take the order up)

#include <chrono>
#include <deque>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "services/node/gripper.hpp"
#include "services/node/sim_requests.hpp"
#include "services/runtime/basic_block.hpp"
#include "twin/orchestration/assembly_script.hpp"
#include "twin/orchestration/booking.hpp"
#include "twin/orchestration/execution_model.hpp"
#include "twin/planning/assembly_planner.hpp"
#include "twin/report/timeline.hpp"

namespace twin {

struct OrderSettings {
  std::string order_id;
  std::chrono::milliseconds wait_timeout{30000};  // for the cell, and for each call but a station's queue
  std::chrono::milliseconds cleanup_timeout{5000};
  // A command nothing was heard of is sent again (the resource carries it out once): DDS
  // matches each pair of endpoints on its own, and a young twin's first commands or a
  // resource's first events may find the other side not matched yet.
  std::chrono::milliseconds resend_after{2000};
  double arm_speed = 0.25;          // m/s: virtual assembly's moves, until an arm's capability says
  double arm_angular_speed = 1.0;   // rad/s
  fb::GripperGeometry gripper;     // the cell's (deployment key `gripper:`), as the plan used it
  // How it plans again when virtual assembly finds no path (back to sequence planning), as the
  // first plan was made: the cell's fixtures, and `stop`, asked between the search's steps.
  PlannerOptions replanning;
  // Taking up an order whose earlier twin ended during physical assembly (assembly_script.hpp).
  Resume resume;
  // A resource it hired restarted under its work (services/node/restart_reason.hpp): end
  // this twin at once, releasing nothing, so that the next twin the cell starts takes the
  // order up from the cell's state. Off: the order fails.
  bool take_up_after_restart = false;
  // Plan and assemble virtually, then ask for quotes instead of booking: no station, no
  // stock, nothing physical. The final status is the caller's (it prices the quote).
  bool quote_only = false;
  // The cell's real-time factor as the twin last heard it: what the cell's messages cost in
  // sim time (MessageCosts). Unset: nothing.
  std::function<double()> real_time_factor;
};

enum class Phase { idle, waiting_cell, virtual_assembly, booking, queued, hiring, physical, quoting, cleanup, ended };

class OrderOrchestrator : public fb::BasicChart<Phase> {
 public:
  OrderOrchestrator(std::string name, const LoadedProduct& product, const Plan& plan, OrderSettings settings);

  // The plan as virtual assembly left it: the sequence (replanned if cell-sim made it go
  // back), each step done so far with the trajectory cell-sim validated.
  const Plan& plan() const { return plan_; }
  const std::string& error() const { return error_; }
  bool take_up() const { return take_up_; }
  // The commands sent for the order, with when each ran in sim time (its events'), in order.
  const Timeline& timeline() const { return timeline_; }
  // How long physical assembly would hold `station` (and its arm), in s of sim time: the
  // order's script at that station timed against its arm's model (execution_model.hpp), the
  // parts at the dock; while its place is not heard of (a capability that lapsed), the hold
  // last known there, or -1. Bids to host the order are weighed by it (ModelledFinish,
  // order_network.hpp): each station is offered the same call.
  double hold_at(const std::string& station) const;

 private:
  using Action = ScriptAction;
  struct Place {
    std::string kind;
    fb::Numbers position, dock;
    double speed = 0, angular_speed = 0;
    std::string reserved_by;
    std::vector<std::string> waiting;
  };

  // Booking and hiring.
  void try_begin_virtual();  // CELL_READY once cell-sim answered and a station is known
  void begin_virtual();
  void book(std::string only = "");  // `only`: call that station alone
  void on_queue_news(const Place& station);
  void report_place(long ahead);  // "waiting for station-1: N orders ahead", when N changed
  void consider_moving_to(const std::string& station);
  void on_resource_gone(const std::string& id);
  void hire();
  void on_awarded(const fb::Data& award);
  const Place* arm_at(const std::string& station) const;  // its arm, once its capability is heard
  // Quotes.
  void ask_for_quotes();
  void on_quoted(const fb::Data& quote);
  void quote_when_arm_known();
  void start_physical_when_hired();
  // Scripts.
  void add_candidate(std::size_t step, std::size_t candidate);
  void plan_physical();
  void plan_cleanup();
  void add_unit_candidate(std::size_t step, const Trajectory& t);
  fb::Data command(const std::string& resource, const std::string& operation, const std::string& part = "");
  // Running them.
  void next_action();
  void action_done();
  void on_collision(const std::string& reason);
  // No trajectory of the current step's part works in cell-sim: plan the rest again.
  void back_to_sequence_planning();
  void send_command(const fb::Data& command);
  void resend_unheard();
  // cell-sim answered "busy" (its queue was full): the request goes again at the next TICK.
  void ask_sim_again();
  void fail(const std::string& reason);
  void finish();
  void status(const std::string& state, const std::string& message, double progress);
  std::vector<Trajectory> candidates(std::size_t step) const;
  std::string virtual_body(PartIndex part) const;
  Location location(const std::string& resource) const;  // from its capability
  Hired hired() const;        // the station, arm, robot and buffers awarded, with their places
  bool knows_places() const;  // of the station and the buffers: their capabilities were heard
  // The physical script for `h` timed against the resources' models (execution_model.hpp).
  ModelledRun modelled(const Hired& h, double station_free, double robot_free) const;
  std::vector<std::string> virtual_gripper() const;  // its bodies in the order's scene, the palm first
  std::vector<std::string> fetched_types() const;  // of each part a step fetches, in planned order
  bool waited_too_long() const;
  void ask_sim(const fb::Data& request);
  bool sim_silent() const;  // the awaited cell-sim request unanswered for wait_timeout

  const LoadedProduct& product_;
  Plan plan_;
  OrderSettings settings_;
  fb::SimRequests sim_;
  std::map<std::string, Place> places_;  // what capabilities say, by resource id
  std::chrono::steady_clock::time_point waiting_since_;
  CarryGeometry geometry_{product_, plan_};
  Script actions_;
  bool action_running_ = false;
  std::string awaited_id_;
  std::chrono::steady_clock::time_point asked_sim_at_;  // the awaited cell-sim request went out
  bool sim_busy_ = false;
  int busy_answers_ = 0;  // in a row
  static constexpr int kMaxBusyAnswers = 300;  // at a tick each: 30 s
  std::size_t command_count_ = 0;
  std::size_t step_ = 0, candidate_ = 0;
  std::map<std::size_t, std::set<PartIndex>> barred_;  // step -> parts cell-sim refused there
  std::string virtual_station_;
  Location virtual_place_;  // virtual_station_'s place when virtual assembly began
  bool sim_answers_ = false;
  Booking booking_;  // what was called for and awarded (or quoted)
  // hold_at's answers: station -> (what they were computed from, the hold).
  mutable std::map<std::string, std::pair<std::vector<double>, double>> holds_;
  long ahead_ = -1;  // in the station's queue, as last reported
  bool arm_held_ = false;
  double station_wait_ = 0, robot_wait_ = 0;  // quotes: the best bids' queues

  std::set<std::string> delivered_, spawned_;
  struct Sent {
    fb::Data command;
    std::chrono::steady_clock::time_point at;
  };
  std::map<std::string, Sent> unheard_;  // commands sent that no event has answered yet
  std::map<std::string, PartIndex> fetch_of_;
  std::map<std::string, fb::Data> placed_by_;     // release command id -> the PLACED it makes true
  Timeline timeline_;
  std::map<std::string, std::size_t> timeline_index_;  // command id -> its entry
  void record(const fb::Data& event);  // a command event: when its command ran
  std::string error_;
  bool take_up_ = false;
};

}  // namespace twin
