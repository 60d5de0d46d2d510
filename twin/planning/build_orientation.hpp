#pragma once
// The orientation the product is built in (issue #32 item 3). A product is planned as it
// stands finished; where that plan is incomplete, the cell may build it turned, as a person
// builds a table upside down: its top on the bench, the legs put in from above. Each
// orientation is planned like the finished one (every state must stand under gravity, the
// plan is replayed), so a turned plan is complete only where the turned product stands. The
// cell cannot turn a finished product over: a plan in another orientation delivers the
// product so, and its findings say it.

#include <string>
#include <vector>

#include "twin/planning/assembly_planner.hpp"

namespace twin {

struct BuildOrientation {
  std::string name;  // "as finished", "upside down", "on its +x side", ...
  Quat turn = Quat::Identity();  // of the finished product, about its centre
};

// The orientations tried, the finished one first, then upside down, then on each of its four
// sides (the faces of its box: the product's rests where a flat face of it lies on the station).
const std::vector<BuildOrientation>& build_orientations();

// The product turned by `turn` about the centre of its box and set on the station's surface
// (its lowest point at y = 0); x and z of the centre stay where they were.
LoadedProduct turned_product(const LoadedProduct& product, const Quat& turn);

struct OrientedPlan {
  Plan plan;
  BuildOrientation orientation;  // the one the plan builds in
  LoadedProduct product;         // the product in that orientation: what the plan's poses are of
};

// Plans the product as it stands finished; where that plan is incomplete and no overlap of the
// finished product bounds it (a "search-bound" finding: no orientation lifts that), plans it in
// each other orientation in which the finished product stands (unless the cell has fixtures) in
// turn, within what is left of `options.time_limit`, until one is complete. Keeps the complete plan, else the one that holds the most parts (the first on a
// tie), with an "orientation" finding that says which orientations held how many parts and,
// for a turned plan, that the product is delivered so.
OrientedPlan plan_in_build_orientation(const LoadedProduct& product, SequencePlanner& sequence, PathPlanner& path,
                                       const PlannerOptions& options = {});

}  // namespace twin
