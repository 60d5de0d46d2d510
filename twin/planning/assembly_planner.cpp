#include "twin/planning/assembly_planner.hpp"

#include <cstdio>
#include <map>
#include <set>
#include <unordered_set>

namespace twin {
namespace {

std::string millimetres(double metres) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2f mm", metres * 1000);
  return buffer;
}

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

class Search {
 public:
  Search(const LoadedProduct& product, SequencePlanner& sequence, PathPlanner& path, const PlannerOptions& options)
      : product_(product), sequence_(sequence), path_(path), options_(options),
        scene_(product, options.collision, options.arm), assembled_(product.product.parts().size(), false) {}

  Plan run() {
    plan_.sequence_planner = sequence_.name();
    plan_.path_planner = path_.name();
    for (const PlanStep& step : options_.given) {
      assembled_[step.part] = true;
      scene_.assemble(step.part);
      plan_.steps.push_back(step);
    }
    plan_.complete = extend();
    if (!plan_.complete && deepest_.size() > plan_.steps.size()) plan_.steps = deepest_;
    report();
    return std::move(plan_);
  }

 private:
  const std::string& name(PartIndex p) const { return product_.product.parts()[p].name; }

  // Depth-first: returns true once every part is in.
  bool extend() {
    if (plan_.steps.size() == assembled_.size()) return true;
    if (failed_states_.count(assembled_)) return false;
    const std::vector<PartIndex> allowed(scene_.frontier().begin(), scene_.frontier().end());
    for (PartIndex part : sequence_.candidates(scene_)) {
      if (plan_.steps.size() == options_.given.size() && options_.not_next.count(part)) continue;
      std::vector<Attempt> tried;
      std::optional<Trajectory> trajectory;
      while ((trajectory = path_.next(scene_, part, tried))) {
        ++plan_.trajectories_simulated;
        auto collision = scene_.simulate(part, *trajectory);
        if (!collision) break;
        blocked_by_[part].insert(collision->with);
        tried.push_back({std::move(*trajectory), collision});
      }
      if (!trajectory) {
        unplaceable_.insert(part);
        if (!sequence_.backtracks()) return give_up();
        continue;
      }
      assembled_[part] = true;
      scene_.assemble(part);
      plan_.steps.push_back({part, std::move(*trajectory), std::move(tried), allowed});
      if (extend()) return true;
      if (!sequence_.backtracks() || stopped_) return false;
      if (plan_.steps.size() > deepest_.size()) deepest_ = plan_.steps;  // the best partial plan, for the report
      // Partial disassembly: take the part off and try another one in its place.
      plan_.steps.pop_back();
      scene_.disassemble(part);
      assembled_[part] = false;
      ++plan_.backtracks;
      backtracked_.insert(part);
      if (plan_.backtracks >= options_.max_backtracks) {
        stopped_ = true;
        plan_.findings.push_back({"gave-up", "the search stopped after " + std::to_string(plan_.backtracks) + " backtracks", {}});
        return false;
      }
    }
    failed_states_.insert(assembled_);
    return false;
  }

  bool give_up() {
    stopped_ = true;
    return false;
  }

  void report() {
    // Collisions met on the way to the plan, and how each was resolved.
    for (const auto& step : plan_.steps) {
      for (const auto& a : step.failed) {
        plan_.findings.push_back({"collision",
                                  name(step.part) + " (" + a.trajectory.label + "): " + a.collision->member + " hit " +
                                      a.collision->with + " while " + a.collision->phase + ", " +
                                      millimetres(a.collision->depth) + " deep; resolved by " +
                                      step.trajectory.label,
                                  {name(step.part), a.collision->with}});
      }
    }
    if (plan_.backtracks > 0) {
      std::vector<std::string> names;
      for (PartIndex p : backtracked_) names.push_back(name(p));
      plan_.findings.push_back({"backtrack",
                                std::to_string(plan_.backtracks) + " partial disassembl" +
                                    (plan_.backtracks == 1 ? "y" : "ies") + " to find an order; taken off again: " +
                                    join(names),
                                names});
    }
    report_open_order();
    if (!plan_.complete) {
      std::vector<bool> in(assembled_.size(), false);
      for (const auto& s : plan_.steps) in[s.part] = true;
      for (PartIndex p = 0; p < in.size(); ++p) {
        if (in[p]) continue;
        std::vector<std::string> blockers(blocked_by_[p].begin(), blocked_by_[p].end());
        std::string why = unplaceable_.count(p) ? "no collision-free path; blocked by " + join(blockers)
                                                : "never reachable: the parts it is linked to could not be assembled";
        if (unplaceable_.count(p) && blockers.empty()) why = "the path planner had no trajectory for it";
        std::vector<std::string> parts = {name(p)};
        parts.insert(parts.end(), blockers.begin(), blockers.end());
        plan_.findings.push_back({"infeasible", name(p) + ": " + why, parts});
      }
    }
  }

  // Where the links left a choice: the designer steers the sequence through links (paper 5.2).
  void report_open_order() {
    for (std::size_t i = 0; i < plan_.steps.size(); ++i) {
      const auto& allowed = plan_.steps[i].allowed;
      if (allowed.size() < 2) continue;
      std::vector<std::string> names;
      for (PartIndex p : allowed) names.push_back(name(p));
      plan_.findings.push_back({"open-order",
                                "step " + std::to_string(i + 1) + ": the links allow any of " + join(names) +
                                    "; the planner chose " + name(plan_.steps[i].part),
                                names});
    }
  }

  const LoadedProduct& product_;
  SequencePlanner& sequence_;
  PathPlanner& path_;
  const PlannerOptions& options_;
  AssemblyScene scene_;
  std::vector<bool> assembled_;
  Plan plan_;
  std::vector<PlanStep> deepest_;
  std::unordered_set<std::vector<bool>> failed_states_;
  std::map<PartIndex, std::set<std::string>> blocked_by_;
  std::set<PartIndex> unplaceable_;
  std::set<PartIndex> backtracked_;
  bool stopped_ = false;
};

}  // namespace

Plan plan_assembly(const LoadedProduct& product, SequencePlanner& sequence, PathPlanner& path,
                   const PlannerOptions& options) {
  return Search(product, sequence, path, options).run();
}

}  // namespace twin
