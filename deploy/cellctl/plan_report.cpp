#include "deploy/cellctl/plan_report.hpp"

#include "deploy/cellctl/text_table.hpp"

namespace cellctl {
namespace {

// "0.50 back" (what the part came nearest), "0.50 tall (carriage)" (what the gripper did),
// "> 10" (nothing within the reach).
std::string margin_text(const twin::PlanStep& step, double reach) {
  if (!step.margin_measured) return "-";
  if (!step.margin) return "> " + fixed(reach * 1000, 0);
  const twin::Margin& m = *step.margin;
  return fixed(m.distance * 1000, 2) + " " + m.with + (m.member == "part" ? "" : " (" + m.member + ")");
}

}  // namespace

void print_plan(const twin::Product& product, const twin::Plan& plan, std::ostream& out) {
  const std::size_t placed = plan.parts_placed();
  out << "Plan for '" << product.name() << "' (sequence: " << plan.sequence_planner << ", path: " << plan.path_planner
      << "): " << (plan.complete ? "complete" : "INCOMPLETE") << ", " << placed << " of " << product.parts().size()
      << " parts";
  if (!plan.subassemblies.empty()) out << ", " << plan.subassemblies.size() << " subassembl" << (plan.subassemblies.size() == 1 ? "y" : "ies");
  if (plan.orientation != "as finished") out << ", built " << plan.orientation;
  out << "\n\n";
  // A subassembly's own steps read "ShaftPendulum: shaft", built aside; its insertion
  // "ShaftPendulum (shaft, pendulum)".
  TextTable table({"step", "part", "type", "direction", "grasp", "path mm", "margin mm", "tries", "result"});
  for (std::size_t i = 0; i < plan.steps.size(); ++i) {
    const auto& step = plan.steps[i];
    const auto& part = product.parts()[step.part];
    const bool inserts = !step.carried.empty();
    const std::string name = inserts || step.subassembly.empty() ? twin::step_name(product, step) : step.subassembly + ": " + part.name;
    table.add_row({std::to_string(i + 1), name, inserts ? "subassembly" : twin::short_type_name(part.type), step.trajectory.label,
                   step.trajectory.grasp.label + " (" + fixed(step.trajectory.grasp.opening * 1000, 1) + " mm)",
                   fixed(step.trajectory.path_length() * 1000, 1), margin_text(step, plan.margin_reach),
                   std::to_string(step.failed.size() + 1), twin::step_result(step)});
  }
  table.print(out);
  if (plan.verification.run) {
    const auto& v = plan.verification;
    out << "\nVerified: " << (v.passed ? "every step replayed clear" : "NOT every step replayed clear") << " ("
        << v.sweeps << " straight moves and " << v.poses << " poses checked, " << fixed(v.seconds * 1000, 1) << " ms)\n";
  }
  out << "\nFindings:\n";
  if (plan.findings.empty()) out << "  none\n";
  for (const auto& f : plan.findings) out << "  [" << f.kind << "] " << f.message << '\n';
}

}  // namespace cellctl
