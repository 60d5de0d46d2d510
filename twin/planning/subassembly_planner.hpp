#pragma once
// Products with subassemblies (docs/automationml.md, "Subassemblies"): each subassembly is
// planned on its own, as a product of its parts and the links between them, built aside on
// the station; then the product is planned with each subassembly as one rigid body, whose
// links are those of its parts to the rest. The plan lists a subassembly's steps before the
// step that inserts it, in the product's part indices.

#include <string>
#include <vector>

#include "twin/planning/assembly_planner.hpp"

namespace twin {

struct Subassembly {
  std::string name;
  std::vector<PartIndex> members;  // in the product's order; the first is its base
};

// The ID of the part that stands for a subassembly whose base has `base_id` when the product
// is planned with each subassembly as one body.
inline std::string unit_id(const std::string& base_id) { return "subassembly " + base_id; }

// The box of `parts` at their final poses, in the product's frame.
Eigen::AlignedBox3d final_bounds(const LoadedProduct& product, const std::vector<PartIndex>& parts);

// In the order their first parts come in the product.
std::vector<Subassembly> subassemblies_of(const Product& product);

// One body of several parts' meshes, in the frame of `members.front()`: each member's convex
// pieces stay pieces, and a concave one-piece member's triangles each become one, so that
// its bores stay open.
std::shared_ptr<const sim::TriangleMesh> merged_mesh(const LoadedProduct& product, const std::vector<PartIndex>& members);

// One level of a hierarchical plan: a subassembly built aside on its own, or the product
// with each subassembly one part.
struct PlanLevel {
  std::string subassembly;  // the one built at this level; empty: the product
  LoadedProduct product;    // what this level plans, its parts in its own indices
  std::vector<PartIndex> origin;  // each of its parts in the product (a subassembly's: its base)
  std::vector<int> unit;    // the product's level: per part, the subassembly it stands for, or -1
  Vec3 aside;               // a subassembly's level: where it is built, in the product's frame
};

struct PlanLevels {
  std::vector<Subassembly> subassemblies;
  std::vector<PlanLevel> levels;  // in the order the plan builds them: subassemblies, then the product
  // Precedences that cannot hold with each subassembly inserted whole: then the product's
  // level is not there.
  std::vector<std::string> conflicts;
};

PlanLevels plan_levels(const LoadedProduct& product);

// `stability`: the product's own, asked at the product's level of the subassemblies' members.
Plan plan_with_subassemblies(const LoadedProduct& product, SequencePlanner& sequence, PathPlanner& path,
                             const PlannerOptions& options, const StabilityAnalysis& stability);

}  // namespace twin
