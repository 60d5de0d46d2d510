// Products made like CAD exports: one-piece concave meshes with 0.2 mm fits (a C bracket on a
// T rail, a bearing in a housing with a shaft and a pulley), and the same with a shaft 0.4 mm
// too thick. The meshes come from tests/data/planning/make_concave_meshes.py.

#include <algorithm>

#include "tests/twin/test_support.hpp"
#include "twin/planning/assembly_planner.hpp"
#include "twin/planning/interference.hpp"

namespace {

struct Planned {
  explicit Planned(const std::string& file) : loaded(twin::load_product(test::data(file), cache)) {
    twin::SearchSequencePlanner sequence;
    plan = twin::plan_assembly(loaded, sequence, *twin::make_path_planner("linear"));
  }
  const twin::PlanStep& step(const std::string& part) const {
    const auto it = std::find_if(plan.steps.begin(), plan.steps.end(),
                                 [&](const auto& s) { return loaded.product.parts()[s.part].name == part; });
    REQUIRE(it != plan.steps.end());
    return *it;
  }
  twin::PartIndex index(const std::string& part) const { return *loaded.product.find_part_by_name(part); }
  sim::MeshCache cache;
  twin::LoadedProduct loaded;
  twin::Plan plan;
};

}  // namespace

TEST_CASE("CAD products: a C bracket hooks onto a T rail sideways, not from above", "[planning][cad]") {
  const Planned p("planning/rail-bracket/rail-bracket.aml");
  REQUIRE(p.plan.complete);
  const auto& bracket = p.step("bracket");
  CHECK(bracket.trajectory.label == "-x");
  REQUIRE_FALSE(bracket.failed.empty());
  // Straight down, its lip meets the flange: the part itself, by more than the tolerance.
  const auto& down = bracket.failed.front();
  CHECK(down.trajectory.label == "down");
  CHECK(down.collision->with == "rail");
  CHECK(down.collision->member == "part");
  CHECK(down.collision->depth > 0.0003);
}

TEST_CASE("CAD products: 0.2 mm fits of one-piece concave parts go through, a 0.4 mm overlap does not",
          "[planning][cad]") {
  const Planned fits("planning/shaft-bearing/shaft-bearing.aml");
  REQUIRE(fits.plan.complete);
  for (const char* part : {"bearing", "shaft", "pulley"}) CHECK(fits.step(part).trajectory.label == "down");
  // The bearing sinks into the housing's bore: held by its top quarter, the fingers stay out.
  CHECK(fits.step("bearing").trajectory.grasp.label.find("shallow") != std::string::npos);
  CHECK(find_interferences(fits.loaded).overlaps.empty());

  const Planned tight("planning/shaft-bearing/shaft-tight.aml");
  CHECK_FALSE(tight.plan.complete);
  const auto overlaps = find_interferences(tight.loaded).overlaps;
  REQUIRE(overlaps.size() == 2);  // the shaft in the bearing, the pulley on the shaft
  for (const auto& o : overlaps) CHECK(o.depth == Approx(0.0004).margin(0.00005));

  // The sweep sees the same: the thick shaft straight down into the bearing's bore hits it,
  // the right one does not.
  for (const Planned* p : {&fits, &tight}) {
    twin::AssemblyScene scene(p->loaded);
    scene.assemble(p->index("housing"));
    scene.assemble(p->index("bearing"));
    twin::Trajectory down = twin::LinearPathPlanner::straight_insertion(scene, p->index("shaft"), "down", -twin::Vec3::UnitY());
    const auto hit = scene.simulate_grasps(p->index("shaft"), down);
    if (p == &fits) {
      CHECK_FALSE(hit);
    } else {
      REQUIRE(hit);
      CHECK(hit->with == "bearing");
      CHECK(hit->member == "part");
      CHECK(hit->depth > 0.0003);
    }
  }
}
