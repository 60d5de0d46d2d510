// The build orientation (twin/planning/build_orientation.hpp): a product that cannot be built
// as it stands finished is built turned, and the plan says so; one that can is not turned; the
// turned product stands on the station as the finished one did, turned.

#include <catch2/catch.hpp>

#include "tests/support/generated_products.hpp"
#include "twin/planning/build_orientation.hpp"
#include "twin/planning/path_planner.hpp"
#include "twin/report/html_report.hpp"

namespace {

// A small table (a plate on four legs) with a pin put up through the plate's middle from
// below, its head under the plate: as it stands finished the pin cannot go in (from below
// the gripper meets the station, and its shaft in the hole allows no other way), so the
// plan holds 5 of 6 parts. Upside down the plate lies on the station and the pin drops
// into its hole from above, the legs on the plate around it.
twin::LoadedProduct table_with_pin_from_below() {
  test::ProductMaker make("table-with-pin");
  make.part("plate", test::beam_with_holes(0.16, 0.012, 0.12, {{0.0, 0.005, 0.005}}, twin::Vec3(0, 0.04, 0)));
  int n = 0;
  for (double x : {-0.06, 0.06}) {
    for (double z : {-0.04, 0.04}) {
      const std::string leg = "leg" + std::to_string(++n);
      make.part(leg, test::stepped_post({{0.0, 0.04, 0.01, 0.01}}, twin::Vec3(x, 0, z)));
      make.link("plate", leg);
    }
  }
  make.part("pin", test::stepped_post({{0.028, 0.04, 0.012, 0.012}, {0.04, 0.052, 0.0045, 0.0045}}, twin::Vec3::Zero()));
  make.link("plate", "pin");
  return make.take();
}

Eigen::AlignedBox3d world_box(const twin::LoadedProduct& p, twin::PartIndex i) {
  Eigen::AlignedBox3d box;
  for (const auto& v : p.meshes[i]->vertices) box.extend(p.product.parts()[i].final_pose * v);
  return box;
}

}  // namespace

TEST_CASE("build orientation: a product turned upside down stands on the station, turned about its centre",
          "[planning][orientation]") {
  const twin::LoadedProduct finished = table_with_pin_from_below();
  const twin::LoadedProduct turned = twin::turned_product(finished, twin::build_orientations()[1].turn);
  REQUIRE(twin::build_orientations()[1].name == "upside down");
  const auto plate = *finished.product.find_part("plate");
  const auto pin = *finished.product.find_part("pin");
  // The plate's top (y 52 mm) is on the station; the pin's head now lies above the plate.
  CHECK(world_box(turned, plate).min().y() == Approx(0).margin(1e-9));
  CHECK(world_box(turned, plate).max().y() == Approx(0.012).margin(1e-9));
  CHECK(world_box(turned, pin).min().y() == Approx(0).margin(1e-9));
  CHECK(world_box(turned, pin).max().y() == Approx(0.024).margin(1e-9));
  // Over the same place: x unchanged, z mirrored about the product's centre (0).
  CHECK(world_box(turned, plate).center().x() == Approx(world_box(finished, plate).center().x()).margin(1e-9));
  const auto leg1 = *finished.product.find_part("leg1");
  CHECK(world_box(turned, leg1).center().z() == Approx(-world_box(finished, leg1).center().z()).margin(1e-9));
  // The original is untouched.
  CHECK(world_box(finished, plate).min().y() == Approx(0.04).margin(1e-9));
}

TEST_CASE("build orientation: each side is named by the face of the finished product that lies on the station",
          "[planning][orientation]") {
  const twin::LoadedProduct finished = table_with_pin_from_below();
  const auto leg = *finished.product.find_part("leg4");  // at +x, +z
  const auto plate = *finished.product.find_part("plate");
  for (const auto& o : twin::build_orientations()) {
    INFO(o.name);
    const twin::LoadedProduct turned = twin::turned_product(finished, o.turn);
    const Eigen::AlignedBox3d leg_box = world_box(turned, leg), plate_box = world_box(turned, plate);
    if (o.name == "on its +x side" || o.name == "on its +z side") CHECK(leg_box.min().y() < plate_box.center().y());
    if (o.name == "on its -x side" || o.name == "on its -z side") CHECK(leg_box.min().y() > plate_box.center().y());
    if (o.name == "upside down") CHECK(plate_box.min().y() == Approx(0).margin(1e-9));
  }
}

TEST_CASE("build orientation: a table with a pin put in from below is planned upside down, complete and verified",
          "[planning][orientation]") {
  const twin::LoadedProduct product = table_with_pin_from_below();
  auto path = twin::make_path_planner("linear");

  twin::SearchSequencePlanner as_finished;
  const twin::Plan upright = twin::plan_assembly(product, as_finished, *path);
  CHECK_FALSE(upright.complete);
  CHECK(upright.steps.size() == 5);

  twin::SearchSequencePlanner sequence;
  const twin::OrientedPlan oriented = twin::plan_in_build_orientation(product, sequence, *path);
  for (const auto& f : oriented.plan.findings) UNSCOPED_INFO("[" << f.kind << "] " << f.message);
  REQUIRE(oriented.plan.complete);
  CHECK(oriented.plan.verification.passed);
  CHECK(oriented.plan.orientation == "upside down");
  CHECK(oriented.orientation.name == "upside down");
  CHECK(oriented.plan.steps.size() == 6);
  // The plate first, on the station; the plan's poses are the turned product's.
  CHECK(oriented.product.product.parts()[oriented.plan.steps.front().part].name == "plate");
  CHECK(world_box(oriented.product, *product.product.find_part("plate")).min().y() == Approx(0).margin(1e-9));
  const auto said = std::find_if(oriented.plan.findings.begin(), oriented.plan.findings.end(),
                                 [](const twin::Finding& f) { return f.kind == "orientation"; });
  REQUIRE(said != oriented.plan.findings.end());
  CHECK_THAT(said->message, Catch::Contains("built upside down") && Catch::Contains("parts in place as finished: 5 of 6") &&
                                Catch::Contains("delivered upside down"));
  // The designer's report says it at the top.
  CHECK_THAT(twin::html_report(oriented.product, oriented.plan),
             Catch::Contains("6 of 6 parts in 6 steps, built upside down (and delivered so); sequence"));
}

TEST_CASE("build orientation: a product that goes together as it stands is not turned", "[planning][orientation]") {
  test::ProductMaker make("posts");
  make.part("beam", test::beam_with_holes(0.12, 0.02, 0.03, {{-0.03, 0.005, 0.005}, {0.03, 0.005, 0.005}}, twin::Vec3::Zero()));
  make.part("post1", test::stepped_post({{0.0, 0.02, 0.004, 0.004}, {0.02, 0.06, 0.008, 0.008}}, twin::Vec3(-0.03, 0, 0)));
  make.part("post2", test::stepped_post({{0.0, 0.02, 0.004, 0.004}, {0.02, 0.06, 0.008, 0.008}}, twin::Vec3(0.03, 0, 0)));
  make.link("beam", "post1");
  make.link("beam", "post2");
  const twin::LoadedProduct product = make.take();
  twin::SearchSequencePlanner sequence;
  const twin::OrientedPlan oriented = twin::plan_in_build_orientation(product, sequence, *twin::make_path_planner("linear"));
  REQUIRE(oriented.plan.complete);
  CHECK(oriented.plan.orientation == "as finished");
  CHECK(std::none_of(oriented.plan.findings.begin(), oriented.plan.findings.end(),
                     [](const twin::Finding& f) { return f.kind == "orientation"; }));
}
