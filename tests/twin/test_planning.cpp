// Virtual assembly planning on the case studies and on products made to need backtracking
// or to be impossible.

#include <algorithm>

#include <unistd.h>

#include "tests/twin/test_support.hpp"
#include "twin/description/automationml/automationml_description.hpp"
#include "twin/description/automationml/precedence_writer.hpp"
#include "twin/planning/assembly_planner.hpp"
#include "twin/planning/precedence_suggestions.hpp"

namespace {

twin::Plan plan(const std::filesystem::path& file, const std::string& sequence, sim::MeshCache& cache,
                twin::LoadedProduct& loaded, const std::string& path = "linear") {
  loaded = twin::load_product(file, cache);
  auto s = twin::make_sequence_planner(sequence);
  auto p = twin::make_path_planner(path);
  return twin::plan_assembly(loaded, *s, *p);
}

std::vector<std::string> order(const twin::LoadedProduct& loaded, const twin::Plan& plan) {
  std::vector<std::string> names;
  for (const auto& step : plan.steps) names.push_back(loaded.product.parts()[step.part].name);
  return names;
}

std::size_t at(const std::vector<std::string>& order, const std::string& name) {
  const auto it = std::find(order.begin(), order.end(), name);
  REQUIRE(it != order.end());
  return static_cast<std::size_t>(it - order.begin());
}

}  // namespace

TEST_CASE("Cranfield: back first, shaft before pendulum, square pegs before separator, front last", "[planning][cranfield]") {
  for (const char* sequence : {"paper", "search"}) {
    SECTION(sequence) {
      sim::MeshCache cache;
      twin::LoadedProduct loaded{twin::Product("", ""), {}, {}};
      const twin::Plan p = plan(test::product("cranfield/cranfield.aml"), sequence, cache, loaded);
      REQUIRE(p.complete);
      const auto o = order(loaded, p);
      CHECK(o.front() == "back");
      CHECK(o.back() == "front");
      CHECK(at(o, "shaft") < at(o, "pendulum"));
      CHECK(at(o, "boltA1") < at(o, "separator"));
      CHECK(at(o, "boltA2") < at(o, "separator"));
      for (const auto& step : p.steps) {
        const auto& name = loaded.product.parts()[step.part].name;
        if (name.rfind("bolt", 0) == 0) {
          INFO(name);
          CHECK(step.trajectory.label == "down");
          CHECK(step.trajectory.direction.isApprox(-twin::Vec3::UnitY()));
          CHECK(step.failed.empty());
        }
      }
      // The links leave the bolts' order open: the designer is told.
      CHECK(test::has_finding(p, "open-order", "boltR1"));
    }
  }
}

TEST_CASE("Lego tower: bottom-up, and the hanging brick goes in sideways after a collision", "[planning][lego]") {
  for (const char* sequence : {"paper", "search"}) {
    SECTION(sequence) {
      sim::MeshCache cache;
      twin::LoadedProduct loaded{twin::Product("", ""), {}, {}};
      const twin::Plan p = plan(test::product("lego-tower/lego-tower.aml"), sequence, cache, loaded);
      REQUIRE(p.complete);
      // Bottom-up: no brick is assembled before one it stands on.
      for (std::size_t i = 1; i < p.steps.size(); ++i) {
        const auto& part = loaded.product.parts()[p.steps[i].part];
        if (part.name == "hanging") continue;
        CHECK(part.final_pose.translation().y() >=
              loaded.product.parts()[p.steps[i - 1].part].final_pose.translation().y() - 1e-9);
      }
      const auto o = order(loaded, p);
      CHECK(at(o, "overhang") < at(o, "hanging"));
      const auto& hanging = p.steps[at(o, "hanging")];
      REQUIRE_FALSE(hanging.failed.empty());
      CHECK(hanging.failed.front().trajectory.label == "down");
      CHECK(hanging.failed.front().collision->with == "overhang");
      CHECK(std::abs(hanging.trajectory.direction.y()) < 1e-9);  // from the side
      CHECK(test::has_finding(p, "collision", "hanging (down): part hit overhang"));
    }
  }
}

TEST_CASE("backtracking: the paper heuristic stops where the search planner finishes", "[planning][backtrack]") {
  sim::MeshCache cache;
  twin::LoadedProduct loaded{twin::Product("", ""), {}, {}};
  const twin::Plan paper = plan(test::data("planning/backtrack/backtrack.aml"), "paper", cache, loaded);
  CHECK_FALSE(paper.complete);
  CHECK(order(loaded, paper) == std::vector<std::string>{"base", "cap"});
  CHECK(test::has_finding(paper, "infeasible", "block: no collision-free path; blocked by cap"));

  const twin::Plan search = plan(test::data("planning/backtrack/backtrack.aml"), "search", cache, loaded);
  REQUIRE(search.complete);
  CHECK(order(loaded, search) == std::vector<std::string>{"base", "block", "cap"});
  CHECK(search.backtracks == 1);
  CHECK(test::has_finding(search, "backtrack", "cap"));
}

TEST_CASE("a product no order can build is reported with what blocks what", "[planning][impossible]") {
  sim::MeshCache cache;
  twin::LoadedProduct loaded{twin::Product("", ""), {}, {}};
  const twin::Plan p = plan(test::data("planning/impossible/impossible.aml"), "search", cache, loaded);
  CHECK_FALSE(p.complete);
  CHECK(test::has_finding(p, "infeasible", "block: no collision-free path; blocked by shell"));
}

TEST_CASE("the same input gives the same plan", "[planning][determinism]") {
  sim::MeshCache cache;
  twin::LoadedProduct a{twin::Product("", ""), {}, {}}, b{twin::Product("", ""), {}, {}};
  const twin::Plan first = plan(test::product("lego-tower/lego-tower.aml"), "search", cache, a);
  const twin::Plan second = plan(test::product("lego-tower/lego-tower.aml"), "search", cache, b);
  REQUIRE(first.steps.size() == second.steps.size());
  for (std::size_t i = 0; i < first.steps.size(); ++i) {
    CHECK(first.steps[i].part == second.steps[i].part);
    CHECK(first.steps[i].trajectory.label == second.steps[i].trajectory.label);
    CHECK(first.steps[i].trajectory.path_length() == second.steps[i].trajectory.path_length());
  }
  CHECK(first.findings.size() == second.findings.size());
}

TEST_CASE("a given order (a twin taking an order up) is followed, and one that cannot be built is not", "[planning][given]") {
  sim::MeshCache cache;
  twin::LoadedProduct loaded{twin::Product("", ""), {}, {}};
  const twin::Plan searched = plan(test::product("cranfield/cranfield.aml"), "search", cache, loaded);
  REQUIRE(searched.complete);
  std::vector<std::string> given = order(loaded, searched);
  // The links leave the bolts' order open: another order that works.
  std::swap(given[at(given, "boltA1")], given[at(given, "boltR2")]);
  const auto ids = [&](const std::vector<std::string>& names) {  // the planner takes part IDs
    std::vector<std::string> out;
    for (const auto& name : names) out.push_back(test::part(loaded.product, name).id);
    return out;
  };
  const auto path = twin::make_path_planner("linear");
  twin::GivenSequencePlanner followed(ids(given));
  const twin::Plan p = twin::plan_assembly(loaded, followed, *path);
  CHECK(p.complete);
  CHECK(order(loaded, p) == given);
  // The front plate second: the bolts cannot go in after it (or the links do not allow it
  // yet), and the planner does not skip ahead to another part.
  std::vector<std::string> front_early = given;
  front_early.erase(front_early.begin() + at(front_early, "front"));
  front_early.insert(front_early.begin() + 1, "front");
  twin::GivenSequencePlanner wrong(ids(front_early));
  const twin::Plan blocked = twin::plan_assembly(loaded, wrong, *path);
  CHECK_FALSE(blocked.complete);
  CHECK(blocked.steps.size() < given.size());
}

TEST_CASE("no straight insertion: OMPL's RRT-Connect finds a path, checked in the collision world", "[planning][ompl]") {
  sim::MeshCache cache;
  twin::LoadedProduct loaded{twin::Product("", ""), {}, {}};
  const twin::Plan linear = plan(test::data("planning/ledge/ledge.aml"), "search", cache, loaded, "linear");
  CHECK_FALSE(linear.complete);
  CHECK(test::has_finding(linear, "infeasible", "block: no collision-free path"));

  const twin::Plan sampled = plan(test::data("planning/ledge/ledge.aml"), "search", cache, loaded, "ompl");
  REQUIRE(sampled.complete);
  const auto& step = sampled.steps.back();
  CHECK(loaded.product.parts()[step.part].name == "block");
  CHECK(step.trajectory.label == "ompl");
  CHECK(step.failed.size() == 6);  // every straight insertion collided first
  CHECK(step.trajectory.waypoints.size() >= 4);
  // It ends exactly at the part's place, and the whole path is free when run again.
  CHECK(step.trajectory.waypoints.back().part.translation().isApprox(
      loaded.product.parts()[step.part].final_pose.translation()));
  twin::AssemblyScene scene(loaded);
  for (const auto& s : sampled.steps) {
    if (&s == &step) break;
    scene.assemble(s.part);
  }
  CHECK_FALSE(scene.simulate(step.part, step.trajectory));
}

TEST_CASE("lipped box: one-piece concave walls go straight down, the wide block goes in before the last wall",
          "[planning][concave]") {
  sim::MeshCache cache;
  twin::LoadedProduct loaded{twin::Product("", ""), {}, {}};
  const twin::Plan p = plan(test::data("planning/lipped-box/lipped-box.aml"), "search", cache, loaded);
  REQUIRE(p.complete);
  const auto o = order(loaded, p);
  for (const char* wall : {"wall_left", "wall_right", "wall_front", "wall_back"}) {
    const auto& mesh = *loaded.meshes[*loaded.product.find_part_by_name(wall)];
    CHECK_FALSE(mesh.convex);  // a slab and a lip in one piece
    CHECK(p.steps[at(o, wall)].trajectory.label == "down");
  }
  // Too wide for the opening between the lips: in before the last wall, from its side.
  const auto& block = p.steps[at(o, "block")];
  CHECK(at(o, "block") == o.size() - 2);
  CHECK(std::abs(block.trajectory.direction.y()) < 1e-9);

  // Its walls' hulls would fill the space under the lips, where the block stands.
  sim::CollisionWorld world;
  const auto index = [&](const char* name) { return *loaded.product.find_part_by_name(name); };
  world.add_static_mesh("block", loaded.meshes[index("block")], loaded.product.parts()[index("block")].final_pose);
  const auto& wall = loaded.product.parts()[index("wall_left")];
  sim::MovingBody exact, hull;
  exact.add_mesh("part", *loaded.meshes[index("wall_left")], twin::Pose::Identity(), world.options().shape_margin);
  sim::TriangleMesh as_hull = *loaded.meshes[index("wall_left")];
  as_hull.convex = true;
  hull.add_mesh("part", as_hull, twin::Pose::Identity(), world.options().shape_margin);
  CHECK_FALSE(world.penetration(exact, wall.final_pose));
  CHECK(world.penetration(hull, wall.final_pose));
}

TEST_CASE("a mesh in millimetres (LengthUnit mm) is placed and planned in metres", "[planning][units]") {
  sim::MeshCache cache;
  twin::LoadedProduct loaded{twin::Product("", ""), {}, {}};
  const twin::Plan p = plan(test::data("planning/units/units.aml"), "search", cache, loaded);
  REQUIRE(p.complete);
  const auto& block = test::part(loaded.product, "block");
  CHECK(block.mesh->scale == 1e-3);
  CHECK(loaded.meshes[*loaded.product.find_part_by_name("block")]->bounds.sizes().y() == Approx(0.02));
  CHECK(test::position_mm(loaded.product, "block").y() == Approx(10));  // on the 10 mm plate
}

TEST_CASE("a COLLADA mesh states its own unit: it is placed as written, and a LengthUnit on it is an error",
          "[planning][units]") {
  sim::MeshCache cache;
  twin::LoadedProduct loaded{twin::Product("", ""), {}, {}};
  const twin::Plan p = plan(test::data("planning/collada/collada.aml"), "search", cache, loaded);
  REQUIRE(p.complete);
  const auto& mesh = *loaded.meshes[*loaded.product.find_part_by_name("block")];
  CHECK(mesh.bounds.min().isApprox(Eigen::Vector3d::Zero(), 1e-9));  // neither scaled twice nor turned to Y up
  CHECK(mesh.bounds.max().isApprox(Eigen::Vector3d(0.02, 0.02, 0.02), 1e-6));
  CHECK(test::position_mm(loaded.product, "block").y() == Approx(10));  // on the 10 mm plate
  CHECK_THROWS_WITH(twin::AutomationMLDescription(test::data("planning/collada/collada_length_unit.aml")),
                    Catch::Contains("collada_length_unit.aml:24") &&
                        Catch::Contains("LengthUnit does not apply to the COLLADA mesh 'meshes/block_mm_z_up.dae'"));
}

TEST_CASE("insertion margins: the room each part and its gripper have on the way in, seats left out",
          "[planning][margin]") {
  sim::MeshCache cache;
  twin::LoadedProduct loaded{twin::Product("", ""), {}, {}};
  SECTION("Cranfield: every peg has its hole's 0.5 mm of play, and that is under the 1 mm threshold") {
    const twin::Plan p = plan(test::product("cranfield/cranfield.aml"), "search", cache, loaded);
    REQUIRE(p.complete);
    const auto o = order(loaded, p);
    for (const char* peg : {"shaft", "boltA1", "boltA2", "boltR1", "boltR2"}) {
      INFO(peg);
      const auto& step = p.steps[at(o, peg)];
      REQUIRE(step.margin_measured);
      REQUIRE(step.margin);
      CHECK(step.margin->distance == Approx(0.0005).margin(1e-5));
      CHECK(step.margin->with == "back");
      CHECK(step.margin->member == "part");
      CHECK(step.margin->phase == "insert");
      CHECK(test::has_finding(p, "margin", "(" + std::string(peg) + "): the part passes 0.50 mm from back while insert"));
    }
    // The back plate lies on the station: its seat does not count, only the fingers beside it.
    const auto& back = p.steps[at(o, "back")];
    REQUIRE(back.margin);
    CHECK(back.margin->member == "finger");
    CHECK(back.margin->distance > 0.001);
  }
  SECTION("a product made to differ: put in last, the short block's carriage passes 0.5 mm from the tall one") {
    twin::PlannerOptions options;
    loaded = twin::load_product(test::data("planning/margin/margin.aml"), cache);
    auto s = twin::make_sequence_planner("search");
    auto path = twin::make_path_planner("linear");
    const twin::Plan first = twin::plan_assembly(loaded, *s, *path, options);
    REQUIRE(first.complete);
    REQUIRE(order(loaded, first) == std::vector<std::string>{"tall", "short"});
    REQUIRE(first.steps[1].margin);
    CHECK(first.steps[1].margin->member == "carriage");
    CHECK(first.steps[1].margin->with == "tall");
    CHECK(first.steps[1].margin->distance == Approx(0.0005).margin(1e-5));
    CHECK_FALSE(first.steps[0].margin);  // nothing within 10 mm of the first block
    CHECK(test::has_finding(first, "margin", "step 2 (short): the carriage passes 0.50 mm from tall"));

    options.objective = twin::Objective::margin;
    const twin::Plan roomy = twin::plan_assembly(loaded, *s, *path, options);
    REQUIRE(roomy.complete);
    CHECK(order(loaded, roomy) == std::vector<std::string>{"short", "tall"});
    CHECK(twin::least_margin(roomy.steps, options.margin_reach) == Approx(0.0025).margin(1e-5));
    CHECK_FALSE(test::has_finding(roomy, "margin", ""));
    CHECK(test::has_finding(roomy, "margin-search", "least margin of 2.50 mm (the first order found: 0.50 mm)"));

    options.margin_threshold = 0;  // no step is flagged
    CHECK_FALSE(test::has_finding(twin::plan_assembly(loaded, *s, *path, options), "margin", ""));
  }
  SECTION("a one-piece concave part past the triangle limit is not measured, and the findings say so") {
    loaded = twin::load_product(test::data("planning/lipped-box/lipped-box.aml"), cache);
    auto s = twin::make_sequence_planner("search");
    auto path = twin::make_path_planner("linear");
    twin::PlannerOptions options;
    const twin::Plan measured = twin::plan_assembly(loaded, *s, *path, options);
    REQUIRE(measured.complete);
    const auto o = order(loaded, measured);
    const auto& wall = measured.steps[at(o, "wall_left")];
    CHECK(wall.margin_measured);
    const std::size_t triangles = loaded.meshes[*loaded.product.find_part_by_name("wall_left")]->triangles.size();
    REQUIRE(triangles > 4);
    options.margin_max_triangles = triangles - 1;
    const twin::Plan limited = twin::plan_assembly(loaded, *s, *path, options);
    REQUIRE(limited.complete);
    CHECK_FALSE(limited.steps[at(order(loaded, limited), "wall_left")].margin_measured);
    CHECK(test::has_finding(limited, "margin", "(wall_left): margin not measured: one concave piece of " +
                                            std::to_string(triangles) + " triangles"));
    // The block is one convex piece: measured whatever its size.
    CHECK(limited.steps[at(order(loaded, limited), "block")].margin_measured);
  }
}

TEST_CASE("suggested precedences settle the open order: written into the product, it plans the same with fewer choices",
          "[planning][suggest]") {
  sim::MeshCache cache;
  const auto dir = std::filesystem::temp_directory_path() / ("suggest-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  auto sequence = twin::make_sequence_planner("search");
  auto path = twin::make_path_planner("linear");
  const auto count = [](const twin::Plan& p, const std::string& kind) {
    return std::count_if(p.findings.begin(), p.findings.end(), [&](const twin::Finding& f) { return f.kind == kind; });
  };
  const auto replan = [&](const twin::LoadedProduct& loaded, twin::Plan& plan, const twin::PlannerOptions& options,
                          const std::string& name) {
    const auto suggestions = twin::suggest_precedences(loaded, plan, *sequence, *path, options);
    std::vector<std::pair<twin::PartIndex, twin::PartIndex>> rules;
    for (const auto& s : suggestions) rules.emplace_back(s.before, s.after);
    twin::write_with_precedences(loaded.product, rules, dir / name);
    return suggestions;
  };

  SECTION("an order that fails: the block must go in before the cap, or the search goes back") {
    const auto loaded = twin::load_product(test::data("planning/backtrack/backtrack.aml"), cache);
    twin::Plan plan = twin::plan_assembly(loaded, *sequence, *path);
    REQUIRE(plan.complete);
    REQUIRE(plan.backtracks == 1);
    const auto suggestions = replan(loaded, plan, {}, "backtrack.aml");
    REQUIRE(suggestions.size() == 1);
    CHECK(loaded.product.parts()[suggestions[0].before].name == "block");
    CHECK(loaded.product.parts()[suggestions[0].after].name == "cap");
    CHECK(test::has_finding(plan, "suggestion", "step 2: put block before cap: with cap there instead, no order goes together"));

    const auto settled = twin::load_product(dir / "backtrack.aml", cache);  // its meshes copied beside it
    REQUIRE(settled.product.precedences().size() == 1);
    for (const char* planner : {"search", "paper"}) {  // the paper's sequence, which does not go back, now finishes
      INFO(planner);
      auto s = twin::make_sequence_planner(planner);
      const twin::Plan again = twin::plan_assembly(settled, *s, *path);
      REQUIRE(again.complete);
      CHECK(order(settled, again) == order(loaded, plan));
      CHECK(again.backtracks == 0);
      CHECK(count(again, "open-order") < count(plan, "open-order"));
    }
  }
  SECTION("an order with less margin: short before tall, as --prefer margin found") {
    const auto loaded = twin::load_product(test::data("planning/margin/margin.aml"), cache);
    twin::PlannerOptions options;
    options.objective = twin::Objective::margin;
    twin::Plan plan = twin::plan_assembly(loaded, *sequence, *path, options);
    const auto suggestions = replan(loaded, plan, options, "margin.aml");
    REQUIRE(suggestions.size() == 1);
    CHECK(test::has_finding(plan, "suggestion", "put short before tall: with tall there instead, the least margin is 0.50 mm (2.50 mm this way)"));
    const auto settled = twin::load_product(dir / "margin.aml", cache);
    const twin::Plan again = twin::plan_assembly(settled, *sequence, *path);  // not even asked for margin
    CHECK(order(settled, again) == std::vector<std::string>{"short", "tall"});
    CHECK(count(again, "open-order") == 0);
    CHECK(count(plan, "open-order") == 1);
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("planning time: progress is told part by part, and a time limit ends the search with the reason",
          "[planning][time]") {
  const auto loaded = test::load(test::product("cranfield/cranfield.aml"));
  auto sequence = twin::make_sequence_planner("search");
  auto path = twin::make_path_planner("linear");
  twin::PlannerOptions told;
  std::vector<twin::PlanProgress> heard;
  told.progress = [&](const twin::PlanProgress& p) { heard.push_back(p); };
  const twin::Plan plan = twin::plan_assembly(loaded, *sequence, *path, told);
  REQUIRE(plan.complete);
  REQUIRE(heard.size() == plan.steps.size());  // no backtrack: one line per part
  for (std::size_t k = 0; k < heard.size(); ++k) {
    CHECK(heard[k].event == twin::PlanProgress::Event::placed);
    CHECK(heard[k].placed == k + 1);
    CHECK(heard[k].parts == 9);
    CHECK(heard[k].part == loaded.product.parts()[plan.steps[k].part].name);
  }
  // A limit already past: nothing is tried, and the plan says why.
  twin::PlannerOptions hurried;
  hurried.time_limit = 1e-9;
  const twin::Plan stopped = twin::plan_assembly(loaded, *sequence, *path, hurried);
  CHECK_FALSE(stopped.complete);
  const auto gave_up = std::find_if(stopped.findings.begin(), stopped.findings.end(), [](const auto& f) { return f.kind == "gave-up"; });
  REQUIRE(gave_up != stopped.findings.end());
  CHECK(gave_up->message.find("time limit") != std::string::npos);
}
