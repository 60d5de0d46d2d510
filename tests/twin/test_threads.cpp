// Threaded joints: a nut modelled with its thread overlaps its bolt's all round the axis by
// less than a thread's depth. It is taken as a thread, not an interference, and turned on
// along a helix; a plain ring on a plain rod with the same overlap is not. The replay asks the thread every
// third of a turn: a helix off the thread's axis, or of the other hand, fails it.

#include <algorithm>
#include <cmath>
#include <memory>

#include "tests/support/generated_products.hpp"
#include "tests/support/meshes.hpp"
#include "tests/twin/test_support.hpp"
#include "twin/planning/assembly_planner.hpp"
#include "twin/planning/plan_verifier.hpp"
#include "twin/planning/threads.hpp"

namespace {

constexpr double kPitch = 0.002;    // m: M16's coarse pitch, and ISO's for the thread's 14 mm
constexpr double kFine = 0.0015;    // m: a fine pitch (M14 x 1.5)
constexpr double kRoot = 0.006;     // m: the bolt's radius at its thread's roots
constexpr double kHeight = 0.001;   // m: its crests stand this far out
constexpr double kOverlap = 0.0004; // m: the nut's thread reaches this far into the bolt's

// 0 at a root, 1 at a crest, along a right-hand thread.
double ridge(double t, double y, double pitch = kPitch) {
  const double u = (y + pitch * t / (2 * M_PI)) / pitch;
  return std::abs(2 * (u - std::floor(u)) - 1);
}

// A bolt and a nut at the product's origin; `screw_pitch`: a screw link between them that
// declares it (none: 0).
twin::LoadedProduct bolt_and_nut(sim::TriangleMesh bolt_mesh, sim::TriangleMesh nut_mesh, double screw_pitch = 0) {
  test::ProductMaker make("made");
  make.part("bolt", std::move(bolt_mesh));
  make.part("nut", std::move(nut_mesh));
  if (screw_pitch > 0) make.link("bolt", "nut", "screw", screw_pitch);
  return make.take();
}

// Rings of vertices an eighth of the pitch apart along the axis.
int levels(double length, double pitch) { return static_cast<int>(std::lround(8 * length / pitch)); }

// Plain: a rod to the thread's crests.
sim::TriangleMesh bolt(bool threaded = true, double pitch = kPitch) {
  return test::revolved_tube(
      48, levels(0.030, pitch), 0.0, 0.030,
      [threaded, pitch](double t, double y) { return kRoot + kHeight * (threaded ? ridge(t, y, pitch) : 1); },
      [](double, double) { return 0.0; });
}

// Its thread `overlap` into the bolt's, from 14 to 22 mm up; plain: a ring bored to the
// crests' radius less the overlap.
sim::TriangleMesh nut(bool threaded, double pitch = kPitch) {
  return test::revolved_tube(
      48, levels(0.008, pitch), 0.014, 0.022, [](double, double) { return 0.012; },
      [threaded, pitch](double t, double y) {
        return (threaded ? kRoot + kHeight * ridge(t, y, pitch) : kRoot + kHeight) - kOverlap;
      });
}

}  // namespace

TEST_CASE("threads: a nut modelled with its thread into its bolt's is a thread round the bolt's axis, a plain ring on a plain rod is not",
          "[threads]") {
  const twin::LoadedProduct threaded = bolt_and_nut(bolt(), nut(true));
  const auto check = twin::find_interferences(threaded);
  REQUIRE(check.overlaps.size() == 1);
  const auto thread = twin::thread_of(threaded, check.overlaps.front());
  REQUIRE(thread);
  CHECK(std::abs(thread->axis.dot(twin::Vec3::UnitY())) == Approx(1).margin(1e-3));
  CHECK(thread->centre.x() == Approx(0).margin(2e-4));
  CHECK(thread->centre.z() == Approx(0).margin(2e-4));
  CHECK(thread->diameter == Approx(2 * (kRoot + kHeight)).margin(5e-4));
  CHECK(thread->pitch == Approx(kPitch).epsilon(0.01));
  CHECK(thread->pitch_measured);
  CHECK_FALSE(thread->left_hand);
  CHECK(thread->length == Approx(0.008).margin(1e-3));
  CHECK(twin::describe(threaded.product, *thread).rfind("nut in bolt: a thread of 14.", 0) == 0);

  // A plain ring on a plain rod overlaps as much, and has no thread.
  const twin::LoadedProduct plain = bolt_and_nut(bolt(false), nut(false));
  const auto overlaps = twin::find_interferences(plain).overlaps;
  REQUIRE(overlaps.size() == 1);
  CHECK_FALSE(twin::thread_of(plain, overlaps.front()));
}

TEST_CASE("threads: the nut is turned onto the bolt along the thread and verified, a helix off the axis or of the other hand is not",
          "[threads][planning]") {
  const twin::LoadedProduct m = bolt_and_nut(bolt(), nut(true));
  twin::SearchSequencePlanner sequence;
  twin::LinearPathPlanner path;
  const twin::Plan plan = twin::plan_assembly(m, sequence, path);
  for (const auto& f : plan.findings) UNSCOPED_INFO(f.kind + ": " + f.message);
  REQUIRE(plan.complete);
  REQUIRE(plan.steps.size() == 2);
  CHECK(plan.verification.passed);
  const twin::PlanStep& step = plan.steps[1];
  CHECK(m.product.parts()[step.part].name == "nut");
  REQUIRE(step.trajectory.screw);
  CHECK(step.trajectory.screw->mate == 0);
  CHECK(step.trajectory.direction.y() == Approx(-1));  // down the bolt
  // From above the bolt's top (30 mm) to its place (14 mm), and a turn's lead-in.
  CHECK(step.trajectory.screw->turns * kPitch == Approx(0.030 - 0.014 + kPitch).margin(5e-4));
  const auto& w = step.trajectory.waypoints;
  CHECK(std::count_if(w.begin(), w.end(), [](const twin::Waypoint& p) { return p.phase == "screw"; }) > 36 * 8);
  CHECK(std::any_of(plan.findings.begin(), plan.findings.end(), [](const twin::Finding& f) { return f.kind == "thread"; }));

  SECTION("the same helix 1 mm off the thread's axis goes into the bolt") {
    twin::Plan off = plan;
    for (auto& p : off.steps[1].trajectory.waypoints) {
      if (p.phase != "screw") continue;
      p.part.translation().x() += 0.001;
      p.gripper.translation().x() += 0.001;
    }
    const auto v = twin::verify_plan(m, off);
    REQUIRE(v.violations.size() == 1);
    CHECK(v.violations[0].member == "nut");
    CHECK(v.violations[0].step == 2);
    CHECK(v.violations[0].phase == "screw");
    CHECK(v.violations[0].with == "bolt");
  }
  SECTION("turned the wrong way, a left-hand helix goes into the bolt") {
    twin::Plan left = plan;
    const auto& final_pose = m.product.parts()[1].final_pose;
    for (auto& p : left.steps[1].trajectory.waypoints) {
      if (p.phase != "screw") continue;
      // The same height, the turn mirrored: R(-a) where the plan has R(a).
      const Eigen::AngleAxisd turn((final_pose.linear().transpose() * p.part.linear()));
      const twin::Pose grip = p.part.inverse() * p.gripper;
      p.part.linear() = Eigen::AngleAxisd(-turn.angle(), turn.axis()).toRotationMatrix();
      p.gripper = p.part * grip;
    }
    const auto v = twin::verify_plan(m, left);
    REQUIRE(v.violations.size() == 1);
    CHECK(v.violations[0].member == "nut");
    CHECK(v.violations[0].phase == "screw");
    CHECK(v.violations[0].with == "bolt");
  }
}

TEST_CASE("threads: a plain ring overlapping a plain rod is an interference, and no plan holds both", "[threads][planning]") {
  const twin::LoadedProduct m = bolt_and_nut(bolt(false), nut(false));
  twin::SearchSequencePlanner sequence;
  twin::LinearPathPlanner path;
  const twin::Plan plan = twin::plan_assembly(m, sequence, path);
  CHECK_FALSE(plan.complete);
  CHECK(plan.steps.size() == 1);
  CHECK(std::none_of(plan.findings.begin(), plan.findings.end(), [](const twin::Finding& f) { return f.kind == "thread"; }));
}

TEST_CASE("threads: a fine thread is turned at the pitch it is modelled with, measured on its surface, not at ISO's coarse one",
          "[threads][planning]") {
  const twin::LoadedProduct m = bolt_and_nut(bolt(true, kFine), nut(true, kFine));
  const auto overlaps = twin::find_interferences(m).overlaps;
  REQUIRE(overlaps.size() == 1);
  const auto thread = twin::thread_of(m, overlaps.front());
  REQUIRE(thread);
  CHECK(thread->pitch == Approx(kFine).epsilon(0.01));
  CHECK(thread->pitch_measured);
  CHECK(twin::describe(m.product, *thread).find("pitch 1.50 mm (measured on the model)") != std::string::npos);

  twin::SearchSequencePlanner sequence;
  twin::LinearPathPlanner path;
  const twin::Plan plan = twin::plan_assembly(m, sequence, path);
  for (const auto& f : plan.findings) UNSCOPED_INFO(f.kind + ": " + f.message);
  REQUIRE(plan.complete);
  CHECK(plan.verification.passed);
  REQUIRE(plan.steps[1].trajectory.screw);
  CHECK(plan.steps[1].trajectory.screw->pitch == Approx(kFine).epsilon(0.01));

  SECTION("a link that says the thread is ISO's coarse pitch, 2 mm, is refused by the replay") {
    const twin::LoadedProduct linked = bolt_and_nut(bolt(true, kFine), nut(true, kFine), kPitch);
    const twin::Plan declared = twin::plan_assembly(linked, sequence, path);
    CHECK_FALSE(declared.complete);
    CHECK(test::has_finding(declared, "verification", "nut"));
  }
}
