// The search takes a grasp's collision while inserting, releasing or backing out as known
// wherever the part it hit is in place (KnownCollisions): the same plans as running every
// grasp, with fewer grasps run.

#include <catch2/catch.hpp>

#include "tests/support/generated_products.hpp"
#include "tests/support/sanitizers.hpp"
#include "twin/planning/assembly_planner.hpp"
#include "twin/planning/path_planner.hpp"

namespace {

// The linear planner, its trajectories not said to nest: every grasp is run.
class RunEveryGrasp : public twin::LinearPathPlanner {
 public:
  bool trajectories_nest() const override { return false; }
};

std::string steps_of(const twin::Plan& plan, const twin::Product& product) {
  std::string out;
  for (const auto& s : plan.steps) out += product.parts()[s.part].name + " " + s.trajectory.label + " " + s.trajectory.grasp.label + "; ";
  return out;
}

}  // namespace

TEST_CASE("a collision in the insertion recurs while the part it hit is in place, and only then", "[planning][known]") {
  // A post in its mortise, then the beam over its tenon: a beam lowered onto the post's top
  // tenon hits the post wherever the post is in place.
  test::Generated g = test::posts_and_beams(3);
  const auto& product = g.product.product;
  twin::AssemblyScene scene(g.product);
  twin::KnownCollisions known;
  const auto base = *product.find_part_by_name("base"), post = *product.find_part_by_name("post0");
  scene.assemble(base);
  twin::Trajectory down = twin::LinearPathPlanner::straight_insertion(scene, base, "down", -twin::Vec3::UnitY());
  // The base, lowered again onto itself in place, hits it in the insertion on every grasp.
  auto first = scene.simulate_grasps(base, down, &known);
  REQUIRE(first);
  CHECK(first->with == "base");
  CHECK(first->phase == "insert");
  CHECK(known.answered() == 0);
  // With more in place, the same collision is known, not run again.
  scene.assemble(post);
  twin::Trajectory again = twin::LinearPathPlanner::straight_insertion(scene, base, "down", -twin::Vec3::UnitY());
  const auto second = scene.simulate_grasps(base, again, &known);
  REQUIRE(second);
  CHECK(second->with == "base");
  CHECK(known.answered() >= 1);
  // What it hit taken away, it is run again.
  const std::size_t before = known.answered();
  scene.disassemble(base);
  twin::Trajectory free = twin::LinearPathPlanner::straight_insertion(scene, base, "down", -twin::Vec3::UnitY());
  scene.simulate_grasps(base, free, &known);
  CHECK(known.answered() == before);
}

TEST_CASE("plans with the known collisions are the plans of running every grasp", "[planning][known]") {
  const std::uint32_t count = test::kUnderSanitizers ? 4 : 40;
  for (std::uint32_t seed = 1; seed <= count; ++seed) {
    for (const auto& g : {test::posts_and_beams(seed), test::stacked_blocks(seed)}) {
      INFO(g.recipe);
      twin::SearchSequencePlanner sequence_a, sequence_b;
      twin::PlannerOptions options;
      options.max_backtracks = 200;
      twin::LinearPathPlanner known;
      RunEveryGrasp every;
      const twin::Plan a = twin::plan_assembly(g.product, sequence_a, known, options);
      const twin::Plan b = twin::plan_assembly(g.product, sequence_b, every, options);
      CHECK(a.complete == b.complete);
      CHECK(steps_of(a, g.product.product) == steps_of(b, g.product.product));
      CHECK(a.backtracks == b.backtracks);
      CHECK(a.trajectories_simulated == b.trajectories_simulated);
    }
  }
}
