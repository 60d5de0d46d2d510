#pragma once
// An independent check of a plan before it is called complete: every step's whole motion is
// replayed (approach, transit, insertion, release, retreat; the part, what it carries and the
// gripper) against the exact geometry of what stands at that step, by other means than the
// search used. The search asks Bullet (hulls, triangles by GJK/EPA, swept hulls, points of
// crossing triangles); this asks CGAL: where surfaces can meet along a straight move (each
// triangle's swept prism against the other's triangles), and where they do, how deep every
// triangle goes into the other's solid (deepest_inside, searched over the whole triangle). A
// plan that fails it is never reported complete.

#include <optional>
#include <string>
#include <vector>

#include "twin/planning/assembly_planner.hpp"
#include "twin/planning/stability.hpp"

namespace twin {

struct VerifyOptions {
  double contact_tolerance = 3e-4;  // m: deeper is a collision (as planning's)
  // m: where bodies touch, the largest move of any point between two poses checked, and the
  // size down to which a triangle is cut when measuring how deep it goes. Every point deeper
  // than contact_tolerance + 2 x resolution is found; every depth reported is real.
  double resolution = 1.5e-4;
  fb::GripperGeometry gripper;
  // After each step the parts in place must stand (stability.hpp): as the arm leaves them, its
  // part's fastenings not yet made unless the step holds it until they are.
  bool stability = true;
  StabilityOptions stand;
  // The analysis to ask (its contacts and the states it has answered are facts of the
  // product, whoever asked first: the planner shares its own); null: one of the replay's own.
  const StabilityAnalysis* analysis = nullptr;
};

struct Violation {
  std::size_t step = 0;  // 1-based, in the plan's order
  std::string phase;     // of the trajectory ("approach", "insert", "retreat", ...)
  std::string member;    // what moved into something: a part's name, "finger", "palm", "carriage"
  std::string with;      // what it went into: a part's name or "station"
  double depth = 0;      // m, the deepest point found
  Vec3 where = Vec3::Zero();  // that point, in the product's frame
  std::string falls;          // or, after the step, what would not stand (stability.hpp's describe)
  // The depth is how far a surface reached through a mesh that is not closed (it has no
  // inside to measure): through one or the other.
  bool open_surface = false;
};

struct Verification {
  bool verified = false;  // every step replayed and nothing deeper than the tolerance
  std::vector<Violation> violations;  // the first of each step that has one
  std::size_t poses = 0;   // poses checked one by one
  std::size_t sweeps = 0;  // straight moves checked whole
};

// "step 3: the base went 3.85 mm into post_left while insert",
// "step 2: when the arm lets go, post_left: it would topple ..."
std::string describe(const Product& product, const Violation& violation);

// Replays the plan's steps in order. A step's part (a subassembly's insertion: its base and the
// members it carries) moves along its trajectory held by its grasp while the gripper holds it,
// then stays where the trajectory ends, and the gripper moves alone. The station's surface
// (y = 0) and every part in place are obstacles.
Verification verify_plan(const LoadedProduct& product, const Plan& plan, const VerifyOptions& options = {});

}  // namespace twin
