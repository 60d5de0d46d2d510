#pragma once
// Whether an assembly in the making stands under gravity (design.md section 9: gravity is part
// of feasibility). A static analysis of the parts in place, by linear programming: every rigid
// group (the parts a fastening joint holds together: docs/automationml.md, "Joints") that is
// not held must be kept in equilibrium, force and moment, by contact forces inside friction
// cones at its contacts with the station and the other groups, under gravity upright and tilted
// by a margin every way (the disturbance of a cell that moves: a table that is bumped, a part
// set down a little hard). Parts are solids of one density; a contact is where two surfaces
// come within the contact distance, at the corners of the patch they share.
//
// Chosen over settling the assembly in Bullet's dynamics (docs/performance.md, "Gravity"): a
// dynamic body must be convex pieces, and a CAD part's hull fills its bores and mortises.

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "twin/geometry/product_loader.hpp"

namespace twin {

struct StabilityOptions {
  double friction = 0.5;           // Coulomb's coefficient at every contact
  double tilt_margin = 5.0;        // degrees: it must stand with gravity tilted this far, any way
  int tilt_directions = 8;         // ways tilted, evenly around
  double contact_distance = 5e-4;  // m: surfaces this near touch (a clearance fit bears on its bore)
};

// What would move: a rigid group of parts that no forces at its contacts hold.
struct Instability {
  std::vector<PartIndex> parts;  // the group (the part, and what is fastened to it)
  double tilt = 0;               // degrees of tilt at which it can no longer be held (0: upright)
};

// One part where it stands in the state asked about.
struct PlacedPart {
  PartIndex part = 0;
  Pose pose = Pose::Identity();
};

// What the planner asks of gravity: whether the parts stand (StabilityAnalysis::check says
// how). A product planned with its subassemblies as single parts asks it of their members
// (subassembly_planner.cpp): unfastened members do not stand as one rigid body.
class Gravity {
 public:
  virtual ~Gravity() = default;
  virtual std::optional<Instability> check(const std::vector<PlacedPart>& placed, const std::vector<PartIndex>& fixed,
                                           const std::vector<bool>& fastened, std::optional<PartIndex> added) const = 0;
};

class StabilityAnalysis : public Gravity {
 public:
  StabilityAnalysis(const LoadedProduct& product, StabilityOptions options = {});
  ~StabilityAnalysis();
  StabilityAnalysis(const StabilityAnalysis&) = delete;
  StabilityAnalysis& operator=(const StabilityAnalysis&) = delete;

  const StabilityOptions& options() const { return options_; }

  // Whether the parts stand: `fixed` parts (held by the arm) do not move; `fastened` says
  // whether a connection's joint holds (the cell has made it). The first group that would
  // move, or nothing. Contacts are taken between parts where they stand relative to each other
  // as in the finished product (found once per pair), and with the station where a part's
  // lowest points lie on it. A state asked before is answered from memory.
  // `added`: the part just put in, where the state without it is known to stand: then the
  // new part is asked first on its own, the others standing still, and where it stands without
  // leaning on them nothing else need be asked.
  std::optional<Instability> check(const std::vector<PlacedPart>& placed, const std::vector<PartIndex>& fixed = {},
                                   const std::vector<bool>& fastened = {},
                                   std::optional<PartIndex> added = std::nullopt) const override;

 private:
  struct State;
  struct Equilibrium {
    bool holds = true;
    double load_on_assumed = 0;  // the most the parts assumed to stand still bear
  };
  std::optional<Instability> assess(const std::vector<PlacedPart>& placed, const std::vector<PartIndex>& fixed,
                                    const std::vector<bool>& fastened, std::optional<PartIndex> added) const;
  State state(const std::vector<PlacedPart>& placed, const std::vector<PartIndex>& fixed,
              const std::vector<PartIndex>& assumed, const std::vector<bool>& fastened) const;
  bool stacked(const State& state, double tilt) const;
  Equilibrium solve(const State& state, double tilt) const;

  struct Impl;
  std::unique_ptr<Impl> impl_;
  StabilityOptions options_;
};

// "post_left would fall (it cannot be held with gravity tilted 3 degrees)"
std::string describe(const Product& product, const Instability& instability, const StabilityOptions& options);

}  // namespace twin
