// The plan's independent replay (twin/planning/plan_verifier.hpp): a plan that cannot be built
// is never verified, whatever the search believed, and says which step, what went into what
// and how deep; one that can be built is.

#include <fstream>
#include <set>

#include "tests/support/scratch.hpp"
#include "tests/support/wall_product.hpp"
#include "tests/twin/test_support.hpp"
#include "twin/planning/plan_verifier.hpp"

namespace {

std::filesystem::path real(const std::string& relative) { return std::filesystem::path(REAL_DATA_DIR) / relative; }

twin::PartIndex index_of(const twin::LoadedProduct& product, const std::string& name) {
  const auto p = product.product.find_part_by_name(name);
  REQUIRE(p.has_value());
  return *p;
}

// A plan that inserts the parts straight down in the given order, each held by its first grasp,
// as a search that checked nothing would write it.
twin::Plan unchecked_plan(const twin::LoadedProduct& product, const std::vector<std::string>& order) {
  twin::AssemblyScene scene(product);
  twin::Plan plan;
  plan.complete = true;
  for (const auto& name : order) {
    twin::PlanStep step;
    step.part = index_of(product, name);
    step.trajectory = twin::LinearPathPlanner::straight_insertion(scene, step.part, "down", -twin::Vec3::UnitY());
    scene.assemble(step.part);
    plan.steps.push_back(std::move(step));
  }
  return plan;
}

}  // namespace

TEST_CASE("verification: a base beam lowered over posts that stand where it goes is refused, with what and how deep",
          "[verify]") {
  // ASAP's beam frame (tests/data/real): posts 12.7 mm square on tenons that go into the base
  // beam's mortises. Stood on the station first, they are where the base must come down.
  const auto product = test::load(real("asap-beam-frame/asap-beam-frame.aml"));
  const twin::Plan posts_first = unchecked_plan(product, {"post_left", "post_right", "base", "beam_left", "beam_right"});
  // Under gravity the first post would already topple where it stands, on its tenon (its
  // step alone is replayed: the rest of the plan is the geometry's, below).
  twin::Plan first_post = posts_first;
  first_post.steps.resize(1);
  const twin::Verification toppling = twin::verify_plan(product, first_post);
  REQUIRE_FALSE(toppling.violations.empty());
  CHECK(toppling.violations.front().step == 1);
  CHECK(toppling.violations.front().falls.find("post_left: it would topple") == 0);
  // Without gravity, the base's way down over the posts.
  twin::VerifyOptions geometry_only;
  geometry_only.stability = false;
  const twin::Verification bad = twin::verify_plan(product, posts_first, geometry_only);
  CHECK_FALSE(bad.verified);
  REQUIRE_FALSE(bad.violations.empty());
  const twin::Violation& v = bad.violations.front();
  CHECK(v.step == 3);
  CHECK(v.member == "base");
  CHECK(v.with.rfind("post_", 0) == 0);
  CHECK(v.depth > 0.001);
  CHECK(twin::describe(product.product, v).find("step 3: the base went") == 0);

  // The order the search finds is built, and replays clear.
  const test::Planned planned(real("asap-beam-frame/asap-beam-frame.aml"));
  REQUIRE(planned.plan.complete);
  CHECK(product.product.parts()[planned.plan.steps.front().part].name == "base");
  CHECK(planned.plan.verification.run);
  CHECK(planned.plan.verification.passed);
}

TEST_CASE("verification: the search does not go on from a base lowered over its posts", "[verify][planning]") {
  // What the cell planned before: posts first, then the base down over them, "complete". The
  // cause was the coarse hull of a CAD part, grown by 3e35 m (tests/sim/test_mesh.cpp).
  const auto product = test::load(real("asap-beam-frame/asap-beam-frame.aml"));
  twin::GivenSequencePlanner posts_first({"post_left", "post_right", "base", "beam_left", "beam_right"});
  // The posts would topple on their tenons: a fixture must hold each. Then the base's way
  // down over them is refused.
  const twin::Plan plan = twin::plan_assembly(product, posts_first, *twin::make_path_planner("linear"));
  CHECK_FALSE(plan.complete);
  REQUIRE(plan.steps.size() == 2);
  CHECK(plan.steps[0].fixture == std::vector<twin::PartIndex>{plan.steps[0].part});
  CHECK(plan.steps[1].fixture == std::vector<twin::PartIndex>{plan.steps[1].part});
  bool base_blocked = false;
  for (const auto& f : plan.findings) {
    base_blocked = base_blocked || (f.kind == "infeasible" && f.message.find("base: no collision-free path; blocked by post") == 0);
  }
  CHECK(base_blocked);
}

TEST_CASE("verification: a shaft 0.4 mm too thick for its bore is refused at its step, 0.2 mm of clearance is not",
          "[verify]") {
  const test::Planned fits(test::data("planning/shaft-bearing/shaft-bearing.aml"));
  REQUIRE(fits.plan.complete);
  CHECK(twin::verify_plan(fits.product, fits.plan).verified);
  // The same plan, with the shaft of the tight variant (11.2 mm in 10.4 mm bores).
  const auto tight = test::load(test::data("planning/shaft-bearing/shaft-tight.aml"));
  const twin::Verification v = twin::verify_plan(tight, fits.plan);
  CHECK_FALSE(v.verified);
  REQUIRE_FALSE(v.violations.empty());
  CHECK(tight.product.parts()[fits.plan.steps[v.violations.front().step - 1].part].name == "shaft");
  CHECK(v.violations.front().member == "shaft");
  CHECK(v.violations.front().with == "bearing");
  CHECK(v.violations.front().depth == Approx(0.0004).margin(0.0002));
}

TEST_CASE("verification: the gripper is replayed too, and so is every stretch between two waypoints", "[verify]") {
  // Two blocks side by side, 0.1 mm apart.
  const test::ScratchDir dir("verify-gripper");
  std::ofstream(dir.path() / "block.obj") << test::wall_block_obj();
  std::ofstream(dir.path() / "wall.aml") << test::wall_aml(2, 1, "block.obj");
  const auto product = test::load(dir.path() / "wall.aml");
  twin::Plan plan = unchecked_plan(product, {"b-0-0", "b-1-0"});

  // Held across x, the second block's fingers go down into the first.
  twin::AssemblyScene scene(product);
  scene.assemble(plan.steps[0].part);
  const auto grasps = scene.grasps(plan.steps[1].part, -twin::Vec3::UnitY());
  const auto across_x = std::find_if(grasps.begin(), grasps.end(), [](const twin::Grasp& g) { return g.label == "across x from above"; });
  REQUIRE(across_x != grasps.end());
  plan.steps[1].trajectory.hold_by(*across_x);
  const twin::Verification fingers = twin::verify_plan(product, plan);
  REQUIRE_FALSE(fingers.violations.empty());
  CHECK(fingers.violations.front().step == 2);
  CHECK(fingers.violations.front().member == "finger");
  CHECK(fingers.violations.front().with == "b-0-0");
  CHECK(fingers.violations.front().depth > 0.003);

  // Held across z, it goes in clear; then a detour sideways through the first block, from a
  // pose beside it to one beyond it (both clear themselves), is caught in between.
  const auto across_z = std::find_if(grasps.begin(), grasps.end(), [](const twin::Grasp& g) { return g.label == "across z from above"; });
  REQUIRE(across_z != grasps.end());
  plan.steps[1].trajectory.hold_by(*across_z);
  REQUIRE(twin::verify_plan(product, plan).verified);
  auto& w = plan.steps[1].trajectory.waypoints;
  twin::Waypoint beside = w.front(), beyond = w.front();
  beside.part.translation() = product.product.parts()[plan.steps[0].part].final_pose.translation() + twin::Vec3(0.03, 0.002, 0);
  beyond.part.translation() = beside.part.translation() - twin::Vec3(0.06, 0, 0);
  beside.phase = beyond.phase = "transit";
  w.insert(w.begin(), {beside, beyond});
  plan.steps[1].trajectory.hold_by(*across_z);
  const twin::Verification detour = twin::verify_plan(product, plan);
  REQUIRE_FALSE(detour.violations.empty());
  CHECK(detour.violations.front().step == 2);
  CHECK(detour.violations.front().phase == "transit");
  CHECK(detour.violations.front().with == "b-0-0");
}

TEST_CASE("verification: the example products' plans replay clear", "[verify]") {
  for (const char* file : {"cranfield/cranfield.aml", "lego-tower/lego-tower.aml"}) {
    const test::Planned p(test::product(file));
    INFO(file);
    REQUIRE(p.plan.complete);
    CHECK(p.plan.verification.passed);
    CHECK(p.plan.verification.sweeps > 0);
  }
}

TEST_CASE("verification: planning without gravity is replayed without it", "[verify][stability]") {
  // Cranfield's front plate stands only once fastened: with gravity on, the arm holds it until
  // then; with gravity off, neither the search nor the replay asks.
  twin::PlannerOptions options;
  options.stability = false;
  const test::Planned p(test::product("cranfield/cranfield.aml"), options);
  REQUIRE(p.plan.complete);
  CHECK(p.plan.verification.passed);
  CHECK(std::none_of(p.plan.steps.begin(), p.plan.steps.end(), [](const twin::PlanStep& s) { return s.hold; }));
}

TEST_CASE("verification: a part a fixture holds stays held, even after a step whose motion is refused", "[verify][stability]") {
  // The Lillagen shelf (IKEA, open meshes): no order stands, so the plan has fixtures; the
  // replay refuses two insertions (a panel through another's open surface). A refused step's
  // fixture still holds its part in the steps after it.
  const test::Planned p(real("ikea-shelf_lillagen_0927/ikea-shelf_lillagen_0927.aml"), test::with_fixtures());
  const twin::Verification v = twin::verify_plan(p.product, p.plan);
  std::set<std::string> held;
  bool motion_refused = false;
  for (std::size_t i = 0; i < p.plan.steps.size(); ++i) {
    for (twin::PartIndex f : p.plan.steps[i].fixture) held.insert(p.product.product.parts()[f].name);
    for (const auto& violation : v.violations) {
      if (violation.step != i + 1) continue;
      INFO(twin::describe(p.product.product, violation));
      if (violation.falls.empty()) {
        motion_refused = true;
        CHECK(violation.open_surface);
        CHECK(violation.depth > 0.01);  // a panel's thickness, 15 mm: no touch
      } else {
        CHECK(held.count(violation.member) == 0);
      }
    }
  }
  CHECK_FALSE(held.empty());
  CHECK(motion_refused);
}
