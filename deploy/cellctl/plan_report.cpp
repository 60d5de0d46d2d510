#include "deploy/cellctl/plan_report.hpp"

#include "deploy/cellctl/text_table.hpp"

namespace cellctl {

void print_plan(const twin::Product& product, const twin::Plan& plan, std::ostream& out) {
  out << "Plan for '" << product.name() << "' (sequence: " << plan.sequence_planner << ", path: " << plan.path_planner
      << "): " << (plan.complete ? "complete" : "INCOMPLETE") << ", " << plan.steps.size() << " of "
      << product.parts().size() << " parts\n\n";
  TextTable table({"step", "part", "type", "direction", "grasp", "path mm", "tries", "result"});
  for (std::size_t i = 0; i < plan.steps.size(); ++i) {
    const auto& step = plan.steps[i];
    const auto& part = product.parts()[step.part];
    table.add_row({std::to_string(i + 1), part.name, twin::short_type_name(part.type), step.trajectory.label,
                   step.trajectory.grasp.label + " (" + fixed(step.trajectory.grasp.opening * 1000, 1) + " mm)",
                   fixed(step.trajectory.path_length() * 1000, 1), std::to_string(step.failed.size() + 1),
                   step.failed.empty() ? "ok" : "ok after " + std::to_string(step.failed.size()) + " collision(s)"});
  }
  table.print(out);
  out << "\nFindings:\n";
  if (plan.findings.empty()) out << "  none\n";
  for (const auto& f : plan.findings) out << "  [" << f.kind << "] " << f.message << '\n';
}

}  // namespace cellctl
