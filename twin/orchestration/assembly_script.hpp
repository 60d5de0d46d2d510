#pragma once
// An order's physical assembly at one station as a script, and the geometry of carrying its
// parts there: pure functions of the product, the plan and the cell's places, with no events.
// The orchestrator sends the script (order_orchestrator.hpp) and carries virtual assembly's
// parts with the same geometry; a quote times the script against the resources' models
// before any of it is sent (execution_model.hpp).

#include <deque>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "services/node/sim_requests.hpp"
#include "services/runtime/event.hpp"
#include "twin/planning/assembly_planner.hpp"

namespace twin {

// Where a resource stands and where parts are handed over to it, in the cell (its capability).
struct Location {
  fb::Numbers position, dock;
};

// One thing the script does, in turn:
//   sim             a request to cell-sim, done when answered
//   command         a command to a resource, done when it succeeds
//   send_heard      a fetch, done once the robot has said anything of it: the robot takes
//                   fetches in the order it hears them, so the next goes only when the last
//                   was heard (a fetch resent after it was lost cannot be overtaken)
//   await_delivery  until the fetch `data.command_id` has delivered its part
struct ScriptAction {
  enum Kind { sim, command, send_heard, await_delivery } kind;
  fb::Data data;
  bool retry_on_collision = false;  // a move of a candidate trajectory in virtual assembly
  bool may_fail = false;            // a removal of a body that may be gone already
};
using Script = std::deque<ScriptAction>;

// The step puts a whole subassembly in (its part is the base; `carried`, the other members).
inline bool inserts_unit(const PlanStep& step) { return !step.carried.empty(); }

// Taking up an order whose earlier twin ended during physical assembly, as the cell's state
// left it: the order books the station its parts stand on, and its steps done are not done
// again.
struct Resume {
  int attempt = 1;                  // this twin's, for command ids of its own
  std::string station;              // where its parts stand ("": nowhere)
  std::set<std::string> placed;     // bodies assembled at their final poses
  std::set<std::string> aside;      // bodies built into a subassembly that stands aside
  std::set<std::string> delivered;  // bodies at the station's dock, not assembled yet
  std::set<std::string> used;       // every body handed out before: a part set aside needs a new one
};

// The gripper's poses for one step: held (up, over what stands, down to where the trajectory
// starts, along it), then after the release (backing out). The last `turning` of `holding`
// turn the part into a thread.
struct Carry {
  std::vector<Pose> holding, retreat;
  std::size_t turning = 0;
};

class CarryGeometry {
 public:
  // `plan` is read at each call: the orchestrator's plan changes when it is planned again.
  CarryGeometry(const LoadedProduct& product, const Plan& plan) : product_(product), plan_(plan) {}

  // A pose of the product's frame at `station`.
  Pose at(const Location& station, const Pose& pose) const;
  // Where the robot puts `part` down at the station's dock: at the height it has in the
  // product, turned as it goes in (`start`: where its trajectory starts, in the cell).
  Pose at_dock(const Location& station, PartIndex part, const Pose& start) const;
  // Step `index`'s part gripped where it stands (`standing`) and carried along `t`.
  Carry carry(const Location& station, std::size_t index, const Trajectory& t, const Pose& standing) const;
  // Where `part` stands in its subassembly built aside, in the product's frame.
  Pose aside_pose(PartIndex part, const SubassemblyPlan& unit) const;
  // The subassembly that `step` builds aside or inserts; nullptr for a single part's step.
  const SubassemblyPlan* subassembly_of(const PlanStep& step) const;

 private:
  // The least height (product frame) at which the part of step `index`, at `pose` turned, and
  // what it carries are carried over what stands: the parts its steps before put in the
  // product, and every subassembly built aside; -inf when nothing stands.
  double carry_height(std::size_t index, const Pose& pose) const;

  const LoadedProduct& product_;
  const Plan& plan_;
};

// Who physical assembly was given to, and where everything stands.
struct Hired {
  std::string order, station, arm, robot;
  std::map<std::string, std::string> buffer_of;  // part type -> buffer
  std::map<std::string, Location> places;        // resource id -> where it stands
};

// A command to `resource` with its id and award (the caller's numbering).
using CommandMaker =
    std::function<fb::Data(const std::string& resource, const std::string& operation, const std::string& part)>;

struct PhysicalScript {
  Script actions;
  std::map<std::string, PartIndex> fetch_of;  // fetch command id -> the part it fetches
  std::map<std::string, fb::Data> placed_by;  // release command id -> the PLACED it makes true
  std::set<std::string> delivered;            // awaited ids true already: parts at the dock
  std::set<std::string> spawned;              // the bodies it puts in cell-sim
};

// Every part spawned at its buffer's dock; the robot's fetches in planned order; for each
// step the arm waits for that part's delivery, grips it at the dock, carries it up and over to
// its trajectory, inserts (a helix into a thread), releases, backs out, connects. A
// subassembly's parts are built so beside the product (its `aside`); the step inserting it
// makes them movable, grips its base with the others carried, and goes the same way. Steps
// `resume` says are done are not done again; what stands is spawned where it stands.
PhysicalScript physical_script(const LoadedProduct& product, const Plan& plan, const CarryGeometry& geometry,
                               const Hired& hired, const Resume& resume, fb::SimRequests& sim,
                               const CommandMaker& command);

fb::Numbers pose_numbers(const std::vector<Pose>& poses);

}  // namespace twin
