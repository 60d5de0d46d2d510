#pragma once
// Virtual assembly planning (paper Fig. 5): ask the sequence planner for the next part, the
// path planner for a trajectory, run it in the collision world; on a collision ask for
// another trajectory; when no candidate part can be inserted, take parts off again and try
// another order (if the sequence planner backtracks). The result is a plan and findings
// for the designer.

#include <algorithm>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "twin/planning/path_planner.hpp"
#include "twin/planning/sequence_planner.hpp"
#include "twin/planning/stability.hpp"

namespace twin {

struct PlanStep {
  PartIndex part = 0;
  Trajectory trajectory;
  std::vector<Attempt> failed;  // collided tries before the one that worked
  std::vector<PartIndex> allowed;  // what the links allowed at this step (the part among them)
  // A step of a subassembly's own plan (`carried` empty: built aside, its trajectory ends at
  // the part's final pose moved by the subassembly's `aside`), or the step that inserts the
  // whole subassembly: `part` is its base, whose trajectory this is, and `carried` the other
  // members, which move with it at their places relative to the base.
  std::string subassembly;
  std::vector<PartIndex> carried;
  // The least room on the way in (AssemblyScene::margin); nothing: more than the reach.
  std::optional<Margin> margin;
  bool margin_measured = false;
  // The arm keeps the part until the cell has made its fastening (a screw turned, a press fit
  // pressed home) and lets go after: released before, it would not stand.
  bool hold = false;
  // Parts a fixture holds from this step on, where no order stands (PlannerOptions::fixtures).
  std::vector<PartIndex> fixture;
};

struct SubassemblyPlan {
  std::string name;
  std::vector<PartIndex> members;  // the first is its base
  Vec3 aside = Vec3::Zero();       // where it is built: its parts' final poses moved by this
};

struct Finding {
  std::string kind;  // "collision", "backtrack", "open-order", "infeasible", "gave-up"
  std::string message;
  std::vector<std::string> parts;
};

// The independent replay of the plan (plan_verifier.hpp).
struct PlanVerification {
  bool run = false;     // replayed (PlannerOptions::verify)
  bool passed = false;  // every step clear
  std::size_t poses = 0, sweeps = 0;  // checked
  double seconds = 0;
};

struct Plan {
  // Every part in, and (where verification runs) every step replayed clear: the promise the
  // cell is given.
  bool complete = false;
  std::vector<PlanStep> steps;
  std::vector<Finding> findings;
  std::string sequence_planner;
  std::string path_planner;
  std::size_t backtracks = 0;
  std::size_t trajectories_simulated = 0;
  std::vector<SubassemblyPlan> subassemblies;  // each one's steps come before the step inserting it
  double margin_threshold = 0, margin_reach = 0;  // m, as planned with (PlannerOptions)
  PlanVerification verification;
  bool stability = false;  // every state asked whether it stands (PlannerOptions::stability)
  // How the product stands while it is built, and as the cell delivers it (build_orientation.hpp).
  std::string orientation = "as finished";

  // Parts put in: a subassembly's step that sets it in place puts in none of its own.
  std::size_t parts_placed() const {
    return static_cast<std::size_t>(std::count_if(steps.begin(), steps.end(), [](const PlanStep& s) { return s.carried.empty(); }));
  }
};

// How the search goes, for a person waiting: each part put in and each one taken off again.
struct PlanProgress {
  enum class Event { placed, backtrack };
  Event event = Event::placed;
  std::string part;
  std::size_t placed = 0, parts = 0;  // in place now, of
  std::size_t backtracks = 0;
  double seconds = 0;  // since the search began
};

// What a search that goes back looks for among the orders the links allow.
enum class Objective {
  feasible,  // the first order that goes together
  margin,    // of those that do, the one whose least insertion margin is largest
};

struct PlannerOptions {
  std::size_t max_backtracks = 10000;  // bounds the search on products that cannot be built
  // s of wall time the search may take (0: no limit); at the limit it ends with the plan that
  // holds the most parts so far and says why.
  double time_limit = 0;
  std::function<void(const PlanProgress&)> progress;  // told as the search goes, when set
  // Asked as the search goes, between its steps (often: keep it cheap); true ends it where it
  // stands, as the time limit does (the order was cancelled, the process is asked to end).
  std::function<bool()> stop;
  // Planning on from a partial assembly (virtual assembly has done these steps; they stand),
  // with `not_next` barred from being the next part after them (cell-sim found no path for
  // it there): the twin's way back to sequence planning.
  std::vector<PlanStep> given;
  std::set<PartIndex> not_next;
  sim::CollisionOptions collision;
  fb::GripperGeometry gripper;
  Objective objective = Objective::feasible;
  double margin_threshold = 0.001;  // m: a step with less room is a finding
  double margin_reach = 0.010;      // m: margins are measured up to this; 0: not measured
  // A one-piece concave part with more triangles is not measured (a finding says so): its
  // margin is a distance query per pair of its triangles and those near it (a part of 50k
  // triangles: about 0.1 s a step). Parts authored as convex pieces are measured at any size.
  std::size_t margin_max_triangles = 50000;
  // Replay the plan found, independently of the search, before it is called complete
  // (plan_verifier.hpp); `verify_resolution`: its VerifyOptions::resolution.
  bool verify = true;
  double verify_resolution = 1.5e-4;
  // Every state after a step must stand under gravity (stability.hpp); a part that would not
  // is not put in there, and the search looks for an order that puts supports first.
  bool stability = true;
  StabilityOptions stand;
  // Asked instead of the product's own StabilityAnalysis where set (the level of a product
  // whose subassemblies are single parts asks it of their members: subassembly_planner.cpp).
  const Gravity* gravity = nullptr;
  // The cell can hold a part that stands on nothing yet in a fixture: where no order stands,
  // such a plan is complete with 'fixture' findings; without, it is not.
  bool fixtures = false;
};

// Margins closer than this are taken as equal, m: Objective::margin takes an order as better
// only by more than this, and so do the suggestions. Without it, orders whose least margins
// differ by the mesh's rounding (Cranfield's 0.4976 and 0.5000 mm) are all searched.
constexpr double kMarginResolution = 5e-5;

// The least margin of the steps (the reach where none came nearer).
double least_margin(const std::vector<PlanStep>& steps, double reach);

// What a step puts in: the part's name, or for a subassembly's insertion its name and its
// parts' ("ShaftPendulum (shaft, pendulum)").
std::string step_name(const Product& product, const PlanStep& step);

// How a step went, for tables: "ok", "ok after 2 collision(s)", "... , held until fastened".
std::string step_result(const PlanStep& step);

// A product with subassemblies is planned in a hierarchy (subassembly_planner.hpp); `given`
// steps are for a product without.
Plan plan_assembly(const LoadedProduct& product, SequencePlanner& sequence, PathPlanner& path,
                   const PlannerOptions& options = {});

}  // namespace twin
