// The parallel gripper's grasps: which ones a part has, in which order, and how virtual
// assembly picks one that is free of collisions.

#include "tests/twin/test_support.hpp"
#include "twin/planning/assembly_planner.hpp"

namespace {

using twin::Vec3;

twin::Pose at(const Vec3& position) {
  twin::Pose p = twin::Pose::Identity();
  p.translation() = position;
  return p;
}

twin::Plan plan_of(const twin::LoadedProduct& loaded, const twin::PlannerOptions& options = {}) {
  twin::SearchSequencePlanner sequence;
  return twin::plan_assembly(loaded, sequence, *twin::make_path_planner("linear"), options);
}

bool has_finding(const twin::Plan& plan, const std::string& kind, const std::string& text) {
  for (const auto& f : plan.findings) {
    if (f.kind == kind && f.message.find(text) != std::string::npos) return true;
  }
  return false;
}

}  // namespace

TEST_CASE("grasps: behind the push first, the narrower faces first, never ahead of the push", "[planning][grasp]") {
  // A 16 x 24 x 10 mm block standing at (0.1, 0, 0), pushed down.
  const Eigen::AlignedBox3d box(Vec3(0.092, 0, -0.005), Vec3(0.108, 0.024, 0.005));
  const fb::GripperGeometry gripper;
  const auto grasps = twin::grasps_for(box, at(Vec3(0.1, 0, 0)), -Vec3::UnitY(), gripper);
  REQUIRE(grasps.size() == 20);  // five sides, two pairs of faces each, two depths
  CHECK(grasps[0].label == "across z from above");
  CHECK(grasps[0].opening == Approx(0.010));
  CHECK(grasps[1].label == "across z from above, shallow");
  CHECK(grasps[2].label == "across x from above");
  for (const auto& g : grasps) {
    INFO(g.label);
    const twin::Pose world = at(Vec3(0.1, 0, 0)) * g.gripper;
    // The carriage (the gripper's +Y) never points down, where the part goes.
    CHECK(world.linear().col(1).dot(-Vec3::UnitY()) < 0.5);
    CHECK(world.linear().determinant() == Approx(1));
  }
  // From above, the fingers (30 mm) reach half-way down the 24 mm block: the palm's
  // underside stands 18 mm above its top (the gripper's origin is the palm's centre).
  CHECK((at(Vec3(0.1, 0, 0)) * grasps[0].gripper).translation().isApprox(
      Vec3(0.1, 0.024 + 0.018 + gripper.palm_thickness / 2, 0), 1e-12));
  // A shallow grasp, a quarter of the way down: 6 mm.
  CHECK((at(Vec3(0.1, 0, 0)) * grasps[1].gripper).translation().isApprox(
      Vec3(0.1, 0.024 + 0.024 + gripper.palm_thickness / 2, 0), 1e-12));

  // Pushed along +x: the carriage behind, on -x, comes first; none stands on +x.
  const auto sideways = twin::grasps_for(box, at(Vec3(0.1, 0, 0)), Vec3::UnitX(), gripper);
  CHECK(sideways.front().label == "across z from -x");
  for (const auto& g : sideways) CHECK(g.label.find("from +x") == std::string::npos);

  // Wider than the gripper opens across every pair of faces: no grasp.
  const Eigen::AlignedBox3d crate(Vec3(-0.125, 0, -0.125), Vec3(0.125, 0.25, 0.125));
  CHECK(twin::grasps_for(crate, twin::Pose::Identity(), -Vec3::UnitY(), gripper).empty());
}

TEST_CASE("grasps: a bushing beside a tall panel is held from the side away from it", "[planning][grasp]") {
  sim::MeshCache cache;
  const auto loaded = twin::load_product(test::data("planning/grasp/grasp.aml"), cache);
  const twin::Plan plan = plan_of(loaded);
  REQUIRE(plan.complete);
  REQUIRE(plan.steps.size() == 2);
  const auto& step = plan.steps[1];
  CHECK(loaded.product.parts()[step.part].name == "bushing");
  CHECK(step.trajectory.label == "down");
  CHECK(step.trajectory.grasp.label == "across z from -x");
  CHECK(step.trajectory.grasp.opening == Approx(0.016));
  // The gripper follows the part by that grasp until the release, then backs away along -x.
  for (const auto& w : step.trajectory.waypoints) {
    if (w.phase == "retreat") {
      CHECK(w.gripper.translation().x() < (w.part * step.trajectory.grasp.gripper).translation().x() - 0.01);
    } else {
      CHECK(w.gripper.isApprox(w.part * step.trajectory.grasp.gripper, 1e-12));
    }
  }

  // Why: held from above, the gripper hits the panel; the part itself is free.
  twin::AssemblyScene scene(loaded);
  scene.assemble(plan.steps[0].part);
  twin::Trajectory from_above = step.trajectory;
  const auto grasps = scene.grasps(step.part, from_above.direction);
  REQUIRE(grasps.front().label.find("from above") != std::string::npos);
  from_above.hold_by(grasps.front());
  const auto hit = scene.simulate(step.part, from_above);
  REQUIRE(hit);
  CHECK(hit->with == "panel");
  CHECK(hit->member != "part");
  // And simulate_grasps finds the same grasp the plan has.
  CHECK_FALSE(scene.simulate_grasps(step.part, from_above));
  CHECK(from_above.grasp.label == "across z from -x");
}

TEST_CASE("grasps: a part no grasp takes is reported with what the gripper hit", "[planning][grasp]") {
  sim::MeshCache cache;
  const auto loaded = twin::load_product(test::data("planning/grasp/wide-sheet.aml"), cache);
  const twin::Plan plan = plan_of(loaded);
  CHECK_FALSE(plan.complete);
  CHECK(has_finding(plan, "infeasible", "sheet: no collision-free path; the gripper hit station on every grasp"));
}

TEST_CASE("grasps: a smaller gripper from the deployment file leaves a part it cannot open around", "[planning][grasp]") {
  sim::MeshCache cache;
  const auto loaded = twin::load_product(test::data("planning/grasp/grasp.aml"), cache);
  twin::PlannerOptions options;
  options.gripper.max_opening = 0.012;  // the panel (4 mm) fits, the bushing (16 mm) does not
  const twin::Plan plan = plan_of(loaded, options);
  CHECK_FALSE(plan.complete);
  CHECK(has_finding(plan, "infeasible", "bushing: no grasp: it is 16.00 mm across at its narrowest, 4.00 mm more than the gripper opens"));
}
