#pragma once
// Where the links leave the order open, which precedences would settle it (paper 5.2: the
// designer steers the sequence). At each step that allowed several parts, each other allowed
// part is tried next instead, planning on from the plan's steps before it: where that fails,
// or leaves less insertion margin, or would be taken before the plan's part although it is
// no better, the plan's part should go in first. The designer writes them into the product
// as AssemblyPrecedence (docs/automationml.md); planned again, the product gives the same
// plan with fewer open choices.

#include <string>
#include <vector>

#include "twin/planning/assembly_planner.hpp"

namespace twin {

struct PrecedenceSuggestion {
  PartIndex before = 0, after = 0;
  std::size_t step = 0;  // of the plan (0-based) where the links let `after` come instead
  std::string why;
};

// Adds a "suggestion" finding to the plan for each. A product with subassemblies gets them
// level by level (plan_levels): within each subassembly among its parts, and in the product
// among its parts and subassemblies, where a rule names the subassembly by its base part.
std::vector<PrecedenceSuggestion> suggest_precedences(const LoadedProduct& product, Plan& plan, SequencePlanner& sequence,
                                                      PathPlanner& path, const PlannerOptions& options);

}  // namespace twin
