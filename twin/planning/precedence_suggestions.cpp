#include "twin/planning/precedence_suggestions.hpp"

#include <algorithm>
#include <cstdio>

#include "twin/planning/subassembly_planner.hpp"

namespace twin {
namespace {

// Each alternative is searched this far: a part that cannot come next is most often shown so
// by an exhaustive search, which on Cranfield took a minute for all its alternatives.
constexpr std::size_t kMaxBacktracks = 300;

std::string mm(double metres) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2f mm", metres * 1000);
  return buffer;
}

// The suggestions of one product without subassemblies and its plan. `origin`: each of its
// parts in the whole product; `offset`: the plan's first step in the whole plan; the
// findings go to `whole`.
void suggest_at(const LoadedProduct& product, const Plan& plan, const std::vector<PartIndex>& origin, std::size_t offset,
                SequencePlanner& sequence, PathPlanner& path, const PlannerOptions& options,
                std::vector<PrecedenceSuggestion>& out, Plan& whole) {
  const auto& parts = product.product.parts();
  const double least = least_margin(plan.steps, options.margin_reach);
  AssemblyScene scene(product, options.collision, options.gripper);
  for (std::size_t i = 0; i < plan.steps.size(); ++i) {
    const PlanStep& step = plan.steps[i];
    if (step.allowed.size() >= 2) {
      const std::vector<PartIndex> order = sequence.candidates(scene);
      const auto rank = [&](PartIndex p) { return std::find(order.begin(), order.end(), p) - order.begin(); };
      for (PartIndex other : step.allowed) {
        if (other == step.part) continue;
        PlannerOptions instead = options;
        instead.objective = Objective::feasible;
        instead.max_backtracks = std::min(options.max_backtracks, kMaxBacktracks);
        instead.given.assign(plan.steps.begin(), plan.steps.begin() + static_cast<std::ptrdiff_t>(i));
        for (PartIndex p : step.allowed) {
          if (p != other) instead.not_next.insert(p);
        }
        const Plan alternative = plan_assembly(product, sequence, path, instead);
        const double room = least_margin(alternative.steps, options.margin_reach);
        std::string why;
        const bool gave_up = std::any_of(alternative.findings.begin(), alternative.findings.end(),
                                         [](const Finding& f) { return f.kind == "gave-up"; });
        if (!alternative.complete) {
          why = "with " + parts[other].name + " there instead, no order goes together" +
                (gave_up ? " (none in " + std::to_string(instead.max_backtracks) + " backtracks, where the search stopped)"
                         : "");
        } else if (room < least - kMarginResolution) {
          why = "with " + parts[other].name + " there instead, the least margin is " + mm(room) + " (" + mm(least) +
                " this way)";
        } else if (rank(other) < rank(step.part) && room <= least + kMarginResolution) {
          why = "with " + parts[other].name + " there instead, no more room (" + mm(room) +
                "), and the planner would take it first";
        }
        if (why.empty()) continue;
        out.push_back({origin[step.part], origin[other], offset + i, why});
        whole.findings.push_back({"suggestion",
                                  "step " + std::to_string(offset + i + 1) + ": put " + parts[step.part].name + " before " +
                                      parts[other].name + ": " + why,
                                  {parts[step.part].name, parts[other].name}});
      }
    }
    scene.assemble(step.part);
  }
}

}  // namespace

std::vector<PrecedenceSuggestion> suggest_precedences(const LoadedProduct& product, Plan& plan, SequencePlanner& sequence,
                                                      PathPlanner& path, const PlannerOptions& options) {
  std::vector<PrecedenceSuggestion> out;
  if (!plan.complete) return out;
  if (subassemblies_of(product.product).empty()) {
    std::vector<PartIndex> same(product.product.parts().size());
    for (PartIndex p = 0; p < same.size(); ++p) same[p] = p;
    suggest_at(product, plan, same, 0, sequence, path, options, out, plan);
    return out;
  }
  // Level by level, each planned as the whole plan planned it: a subassembly's open choices
  // among its own parts, the product's among its parts and subassemblies (a rule that names
  // a subassembly's base holds for the whole subassembly).
  std::size_t offset = 0;
  for (const PlanLevel& level : plan_levels(product).levels) {
    const Plan own = plan_assembly(level.product, sequence, path, options);
    if (!own.complete) return out;
    suggest_at(level.product, own, level.origin, offset, sequence, path, options, out, plan);
    offset += own.steps.size();
  }
  return out;
}

}  // namespace twin
