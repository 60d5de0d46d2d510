#include "twin/report/plan_json.hpp"

namespace twin {
namespace {

// The thread a step turns its part into (Trajectory::screw), or null.
nlohmann::json screw_json(const Product& product, const Trajectory& t) {
  if (!t.screw) return nullptr;
  const Screw& s = *t.screw;
  return {{"into", product.parts()[s.mate].name}, {"turns", s.turns}, {"pitch", s.pitch},
          {"axis", {s.axis.x(), s.axis.y(), s.axis.z()}}, {"point", {s.point.x(), s.point.y(), s.point.z()}}};
}

nlohmann::json vec(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
nlohmann::json quat(const Pose& p) {
  const Quat q(p.linear());
  return {q.w(), q.x(), q.y(), q.z()};
}

// The least room on the way in; {"more_than": reach} where nothing came that near.
nlohmann::json margin_json(const PlanStep& step, double reach) {
  if (!step.margin_measured) return nullptr;
  if (!step.margin) return {{"more_than", reach}};
  const Margin& m = *step.margin;
  return {{"distance", m.distance}, {"with", m.with}, {"member", m.member}, {"phase", m.phase}};
}

// The parts a fixture holds from this step on, by name.
nlohmann::json fixture_names(const Product& product, const PlanStep& step) {
  nlohmann::json names = nlohmann::json::array();
  for (PartIndex p : step.fixture) names.push_back(product.parts()[p].name);
  return names;
}

}  // namespace

nlohmann::json plan_json(const Product& product, const Plan& plan) {
  nlohmann::json steps = nlohmann::json::array();
  for (std::size_t i = 0; i < plan.steps.size(); ++i) {
    const auto& step = plan.steps[i];
    const auto& part = product.parts()[step.part];
    nlohmann::json trajectory = nlohmann::json::array();
    for (const auto& w : step.trajectory.waypoints) {
      trajectory.push_back({{"phase", w.phase},
                            {"holding", w.holding},
                            {"position", vec(w.part.translation())},
                            {"orientation", quat(w.part)},
                            {"gripper_position", vec(w.gripper.translation())},
                            {"gripper_orientation", quat(w.gripper)}});
    }
    nlohmann::json failed = nlohmann::json::array();
    for (const auto& a : step.failed) {
      failed.push_back({{"label", a.trajectory.label},
                        {"direction", vec(a.trajectory.direction)},
                        {"hit", a.collision->with},
                        {"by", a.collision->member},
                        {"depth", a.collision->depth},
                        {"phase", a.collision->phase}});
    }
    nlohmann::json carried = nlohmann::json::array();
    for (PartIndex p : step.carried) carried.push_back(product.parts()[p].name);
    steps.push_back({{"step", i + 1},
                     {"part", part.name},
                     {"type", short_type_name(part.type)},
                     {"subassembly", step.subassembly.empty() ? nlohmann::json() : nlohmann::json(step.subassembly)},
                     {"carried", carried},
                     {"label", step.trajectory.label},
                     {"direction", vec(step.trajectory.direction)},
                     {"grasp", {{"label", step.trajectory.grasp.label},
                                {"opening", step.trajectory.grasp.opening},
                                {"position", vec(step.trajectory.grasp.gripper.translation())},
                                {"orientation", quat(step.trajectory.grasp.gripper)}}},
                     {"path_length", step.trajectory.path_length()},
                     {"tries", step.failed.size() + 1},
                     {"hold", step.hold},
                     {"screw", screw_json(product, step.trajectory)},
                     {"fixture", fixture_names(product, step)},
                     {"failed_tries", failed},
                     {"margin", margin_json(step, plan.margin_reach)},
                     {"trajectory", trajectory}});
  }
  // The plan as a tree: the product's steps, where a subassembly's insertion holds the steps
  // that build it (by step number).
  nlohmann::json tree = nlohmann::json::array();
  for (std::size_t i = 0; i < plan.steps.size(); ++i) {
    const auto& step = plan.steps[i];
    if (!step.subassembly.empty() && step.carried.empty()) continue;  // under its insertion
    nlohmann::json node = {{"step", i + 1}, {"part", product.parts()[step.part].name}};
    if (!step.carried.empty()) {
      node["subassembly"] = step.subassembly;
      nlohmann::json built = nlohmann::json::array();
      for (std::size_t j = 0; j < plan.steps.size(); ++j) {
        if (plan.steps[j].subassembly == step.subassembly && plan.steps[j].carried.empty()) {
          built.push_back({{"step", j + 1}, {"part", product.parts()[plan.steps[j].part].name}});
        }
      }
      node["built_by"] = built;
      for (const auto& s : plan.subassemblies) {
        if (s.name == step.subassembly) node["built_aside_at"] = vec(s.aside);
      }
    }
    tree.push_back(node);
  }
  nlohmann::json findings = nlohmann::json::array();
  for (const auto& f : plan.findings) findings.push_back({{"kind", f.kind}, {"message", f.message}, {"parts", f.parts}});
  return {{"schema", "agile-cell/plan"},
          {"version", 1},
          {"product", product.name()},
          {"source", product.source().string()},
          {"complete", plan.complete},
          {"sequence_planner", plan.sequence_planner},
          {"path_planner", plan.path_planner},
          {"backtracks", plan.backtracks},
          {"orientation", plan.orientation},
          {"margin_threshold", plan.margin_threshold},
          {"verification", {{"run", plan.verification.run},
                            {"passed", plan.verification.passed},
                            {"stability", plan.stability},
                            {"straight_moves", plan.verification.sweeps},
                            {"poses", plan.verification.poses},
                            {"seconds", plan.verification.seconds}}},
          {"units", {{"length", "m"}}},
          {"steps", steps},
          {"tree", tree},
          {"findings", findings}};
}

}  // namespace twin
