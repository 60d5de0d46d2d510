// The parallel gripper's grasps: which ones a part has, in which order, and how virtual
// assembly picks one that is free of collisions.

#include "tests/support/generated_products.hpp"
#include "tests/support/meshes.hpp"
#include "tests/twin/test_support.hpp"
#include "twin/planning/assembly_planner.hpp"
#include "twin/planning/finger_contact.hpp"
#include "twin/planning/grasp.hpp"

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

// An L in section, extruded along z: a wall x 0..5 mm, y 0..60 mm, and a lip along its foot,
// x 0..40 mm, y 0..5 mm; z -20..20 mm. Closed, one piece, as a CAD export would be.
sim::TriangleMesh l_bracket() {
  const std::vector<std::array<double, 2>> section{{0, 0}, {0.040, 0}, {0.040, 0.005}, {0.005, 0.005}, {0.005, 0.060}, {0, 0.060}};
  sim::TriangleMesh mesh;
  for (const double z : {-0.020, 0.020}) {
    for (const auto& [x, y] : section) mesh.vertices.emplace_back(x, y, z);
  }
  const std::uint32_t n = 6;
  // The two ends: the L as four triangles (a fan from the inner corner, vertex 3).
  for (const auto& [a, b] : std::vector<std::pair<std::uint32_t, std::uint32_t>>{{4, 5}, {5, 0}, {0, 1}, {1, 2}}) {
    mesh.triangles.push_back({3, b, a});
    mesh.triangles.push_back({3 + n, a + n, b + n});
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t j = (i + 1) % n;
    mesh.triangles.push_back({i, j, j + n});
    mesh.triangles.push_back({i, j + n, i + n});
  }
  mesh.pieces.emplace_back();
  for (std::uint32_t i = 0; i < 2 * n; ++i) mesh.pieces.back().push_back(i);
  for (const auto& v : mesh.vertices) mesh.bounds.extend(v);
  return mesh;
}

}  // namespace

TEST_CASE("grasps: behind the push first, the narrower faces first, never ahead of the push", "[planning][grasp]") {
  // A 16 x 24 x 10 mm block standing at (0.1, 0, 0), pushed down.
  const Eigen::AlignedBox3d box(Vec3(0.092, 0, -0.005), Vec3(0.108, 0.024, 0.005));
  const fb::GripperGeometry gripper;
  const auto grasps = twin::grasps_for(box, at(Vec3(0.1, 0, 0)), -Vec3::UnitY(), gripper);
  REQUIRE(grasps.size() == 30);  // five sides, two pairs of faces each, three depths
  CHECK(grasps[0].label == "across z from above");
  CHECK(grasps[0].opening == Approx(0.010));
  CHECK(grasps[1].label == "across z from above, shallow");
  CHECK(grasps[2].label == "across z from above, deep");
  CHECK(grasps[3].label == "across x from above");
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
  // A deep one, to 2 mm above its bottom: 22 mm down, the palm 8 mm above its top.
  CHECK((at(Vec3(0.1, 0, 0)) * grasps[2].gripper).translation().isApprox(
      Vec3(0.1, 0.024 + 0.008 + gripper.palm_thickness / 2, 0), 1e-12));

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
  // The panel, 4 mm thin and tall, would topple alone: a fixture holds it (what is asked here
  // is the bushing's grasp).
  const twin::Plan plan = plan_of(loaded, test::with_fixtures());
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
  CHECK(test::has_finding(plan, "infeasible", "sheet: no collision-free path; the gripper hit station on every grasp"));
}

TEST_CASE("grasps: a smaller gripper from the deployment file leaves a part it cannot open around", "[planning][grasp]") {
  sim::MeshCache cache;
  const auto loaded = twin::load_product(test::data("planning/grasp/grasp.aml"), cache);
  twin::PlannerOptions options;
  options.gripper.max_opening = 0.012;  // the panel (4 mm) fits, the bushing (16 mm) does not
  const twin::Plan plan = plan_of(loaded, options);
  CHECK_FALSE(plan.complete);
  CHECK(test::has_finding(plan, "infeasible", "bushing: no grasp: it is 16.00 mm across at its narrowest, 4.00 mm more than the gripper opens"));
}

TEST_CASE("grasps: a finger on a face of a concave part's box may close on air, and such a grasp does not hold it",
          "[planning][grasp]") {
  const sim::TriangleMesh bracket = l_bracket();
  const fb::GripperGeometry gripper;
  std::map<std::string, bool> holds;
  for (const auto& g : twin::grasps_for(bracket.bounds, twin::Pose::Identity(), -Vec3::UnitY(), gripper)) {
    holds[g.label] = twin::fingers_touch(bracket, g, gripper, 0.001);
  }
  // From above, the fingers reach 30 mm down the 60 mm wall: across x, the one at x = 40 mm
  // finds nothing but the lip, 25 mm below its tip; across z, both land in the middle of the
  // box, 15 mm from the wall. From -x, across z, they reach 20 mm in and hold the wall's ends.
  REQUIRE(holds.count("across x from above"));
  CHECK_FALSE(holds["across x from above"]);
  CHECK_FALSE(holds["across x from above, deep"]);
  CHECK_FALSE(holds["across z from above"]);
  CHECK(holds["across z from -x"]);
  // A block is held wherever its box is.
  sim::TriangleMesh block;
  for (const double x : {0.0, 0.040}) {
    for (const double y : {0.0, 0.060}) {
      for (const double z : {-0.020, 0.020}) block.vertices.emplace_back(x, y, z);
    }
  }
  block.triangles = {{0, 1, 3}, {0, 3, 2}, {4, 6, 7}, {4, 7, 5}, {0, 4, 5}, {0, 5, 1},
                     {2, 3, 7}, {2, 7, 6}, {0, 2, 6}, {0, 6, 4}, {1, 5, 7}, {1, 7, 3}};
  for (const auto& v : block.vertices) block.bounds.extend(v);
  for (const auto& g : twin::grasps_for(block.bounds, twin::Pose::Identity(), -Vec3::UnitY(), gripper)) {
    INFO(g.label);
    CHECK(twin::fingers_touch(block, g, gripper, 0.001));
  }
}

TEST_CASE("grasps: low walls are held deep, a grasp that closes on air is said before any move, and another taken", "[planning][grasp]") {
  // The ledge product's enclosure: walls 5 mm high around a cavity, and one 15 mm high. Half
  // way down its 15 mm box the fingers across its 40 mm would close 2.5 mm above the low
  // walls: held deep, to 2 mm above its bottom.
  sim::MeshCache cache;
  const auto ledge = twin::load_product(test::data("planning/ledge/ledge.aml"), cache);
  const twin::Plan plan = plan_of(ledge);
  const auto enclosure = std::find_if(plan.steps.begin(), plan.steps.end(), [&](const auto& s) {
    return ledge.product.parts()[s.part].name == "enclosure";
  });
  REQUIRE(enclosure != plan.steps.end());
  CHECK(enclosure->trajectory.grasp.label == "across z from above, deep");

  // The L bracket alone on the station: held across x from above, a finger closes on air,
  // and virtual assembly says so before any move; the planner holds it from -x instead.
  twin::LoadedProduct alone{twin::Product("bracket", ""), {std::make_shared<sim::TriangleMesh>(l_bracket())}, {}};
  twin::DigitalPart part;
  part.id = "bracket";
  part.name = "bracket";
  part.final_pose = twin::Pose::Identity();
  alone.product.add_part(part);
  twin::AssemblyScene scene(alone);
  twin::Trajectory down = twin::LinearPathPlanner::straight_insertion(scene, 0, "down", -Vec3::UnitY());
  const auto grasps = scene.grasps(0, -Vec3::UnitY());
  const auto on_air = std::find_if(grasps.begin(), grasps.end(), [](const auto& g) { return g.label == "across x from above"; });
  REQUIRE(on_air != grasps.end());
  down.hold_by(*on_air);
  const auto air = scene.simulate(0, down);
  REQUIRE(air);
  CHECK(air->phase == "gripping");
  CHECK(air->member == "finger");
  const twin::Plan plan_alone = plan_of(alone);
  REQUIRE(plan_alone.complete);
  CHECK(scene.holds(0, plan_alone.steps[0].trajectory.grasp));
  CHECK(plan_alone.steps[0].trajectory.grasp.label.find("from -x") != std::string::npos);
}

TEST_CASE("grasps: the footprint's turn is the side of its smallest rectangle", "[planning][grasp]") {
  // A 60 x 20 mm rectangle, 10 mm tall, turned 30 degrees about the vertical.
  std::vector<Vec3> points;
  const Eigen::AngleAxisd turn(-M_PI / 6, Vec3::UnitY());  // takes x to (cos 30, 0, sin 30)
  for (double x : {-0.03, 0.03}) {
    for (double y : {0.0, 0.01}) {
      for (double z : {-0.01, 0.01}) points.push_back(turn * Vec3(x, y, z));
    }
  }
  CHECK(twin::footprint_yaw(points) == Approx(M_PI / 6).margin(1e-9));
  const twin::Pose unturn = twin::unturn_by(twin::footprint_yaw(points));
  Eigen::AlignedBox3d box;
  for (const Vec3& p : points) box.extend(unturn * p);
  CHECK(box.sizes().x() == Approx(0.06).margin(1e-9));
  CHECK(box.sizes().z() == Approx(0.02).margin(1e-9));
  points = {Vec3(0, 0, 0), Vec3(0.05, 0, 0), Vec3(0.05, 0, 0.02), Vec3(0, 0, 0.02)};
  CHECK(twin::footprint_yaw(points) == Approx(0).margin(1e-9));
}

TEST_CASE("grasps: a bar lying turned 45 degrees is held across its own width, not across its box in the world's axes",
          "[planning][grasp]") {
  // 250 x 20 x 20 mm on the station, turned 45 degrees: its box in the world's axes is 191 mm
  // across x and z, wider than this gripper opens (150 mm), and across y a finger would go
  // under it into the station.
  test::ProductMaker make("turned-bar");
  sim::TriangleMesh bar = test::box_mesh(Vec3(0.125, 0.01, 0.01));
  const Eigen::AngleAxisd turn(M_PI / 4, Vec3::UnitY());
  for (auto& v : bar.vertices) v = turn * v + Vec3(0, 0.01, 0);
  bar.bounds = {};
  for (const auto& v : bar.vertices) bar.bounds.extend(v);
  make.part("bar", std::move(bar));
  const twin::LoadedProduct product = make.take();
  twin::PlannerOptions options;
  options.gripper.max_opening = 0.15;
  const twin::Plan plan = plan_of(product, options);
  REQUIRE(plan.complete);
  const twin::Grasp& grasp = plan.steps.front().trajectory.grasp;
  CHECK_THAT(grasp.label, Catch::Contains("turned 45 deg"));
  CHECK(grasp.opening == Approx(0.02).margin(1e-9));
}

TEST_CASE("grasps: beside the centre, the fingers close on the part where they stand", "[planning][grasp]") {
  // A disc 130 mm across, 40 mm tall (a table's base): a quarter of its length from its rim,
  // 32.5 mm off its centre, the fingers (8 mm wide) open to its widest chord between them, at
  // 28.5 mm off the centre: 2 sqrt(65^2 - 28.5^2) = 116.8 mm.
  sim::TriangleMesh disc = test::tube_mesh(256, 0.065, 0, 0.04);
  for (const auto& v : disc.vertices) disc.bounds.extend(v);
  const fb::GripperGeometry gripper;
  const auto centred = twin::grasps_for(disc.bounds, twin::Pose::Identity(), -Vec3::UnitY(), gripper);
  REQUIRE(centred.front().label == "across x from above");
  const auto beside = twin::off_centre_grasps(centred.front(), disc, gripper);
  REQUIRE(beside.size() == 2);
  for (const auto& g : beside) {
    INFO(g.label);
    CHECK_THAT(g.label, Catch::Contains("33 mm off-centre"));
    CHECK(g.opening == Approx(0.1168).margin(0.0005));
    CHECK(std::abs(std::abs(g.gripper.translation().z()) - 0.0325) < 1e-9);
    CHECK(std::abs(g.gripper.translation().x()) < 1e-4);  // the chord is centred on the axis
    CHECK(twin::fingers_touch(disc, g, gripper, 0.001));
  }
  // Where no surface is between the fingers, no grasp: a part shorter than four fingers'
  // widths has none beside its centre.
  sim::TriangleMesh pin = test::box_mesh(Vec3(0.01, 0.02, 0.01));
  CHECK(twin::off_centre_grasps(twin::grasps_for(pin.bounds, twin::Pose::Identity(), -Vec3::UnitY(), gripper).front(),
                                pin, gripper)
            .empty());
}

TEST_CASE("grasps: a bar whose middle has a post beside it is held off its centre", "[planning][grasp]") {
  // A frame of one piece: a plate, end walls 2 mm beyond the bar's ends, and a post 2 mm
  // beside the bar's middle; the bar, 240 x 20 x 20 mm, is lowered onto the plate between
  // them. From above across z a finger at the middle goes into the post; from the ends the
  // carriage meets the walls; from the sides a finger goes under the bar into the plate. A
  // quarter of the way from either end the fingers are clear.
  test::ProductMaker make("bar-by-a-post");
  sim::TriangleMesh frame;
  test::add_box(frame, {-0.130, 0, -0.050}, {0.130, 0.010, 0.050});  // the plate
  frame.pieces.emplace_back();
  test::add_box(frame, {-0.130, 0.010, -0.050}, {-0.122, 0.100, 0.050});  // end walls
  frame.pieces.emplace_back();
  test::add_box(frame, {0.122, 0.010, -0.050}, {0.130, 0.100, 0.050});
  frame.pieces.emplace_back();
  test::add_box(frame, {-0.010, 0.010, 0.012}, {0.010, 0.100, 0.040});  // the post
  make.part("frame", std::move(frame));
  sim::TriangleMesh bar;
  test::add_box(bar, {-0.120, 0.010, -0.010}, {0.120, 0.030, 0.010});
  make.part("bar", std::move(bar));
  make.link("frame", "bar");
  const twin::LoadedProduct product = make.take();
  const twin::Plan plan = plan_of(product);
  std::string findings;
  for (const auto& f : plan.findings) findings += f.kind + ": " + f.message + "\n";
  INFO(findings);
  REQUIRE(plan.complete);
  REQUIRE(plan.steps.size() == 2);
  const twin::Grasp& grasp = plan.steps[1].trajectory.grasp;
  CHECK_THAT(grasp.label, Catch::StartsWith("across z from above") && Catch::Contains("60 mm off-centre"));
  CHECK(grasp.opening == Approx(0.02).margin(1e-9));
}
