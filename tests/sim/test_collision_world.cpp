#include <catch2/catch.hpp>

#include "sim/collision/collision_world.hpp"

namespace {

std::filesystem::path products(const std::string& relative) { return std::filesystem::path(PRODUCTS_DIR) / relative; }

sim::Pose at(double x, double y, double z) {
  sim::Pose p = sim::Pose::Identity();
  p.translation() = Eigen::Vector3d(x, y, z);
  return p;
}

sim::MovingBody box_body(const Eigen::Vector3d& half, const sim::CollisionWorld& world) {
  sim::MovingBody body;
  body.add_box("part", half, sim::Pose::Identity(), world.options().shape_margin);
  return body;
}

}  // namespace

TEST_CASE("touching is not colliding, penetration beyond the tolerance is", "[collision]") {
  sim::CollisionWorld world;
  world.add_static_box("floor", {0.1, 0.01, 0.1}, at(0, -0.01, 0));
  const auto cube = box_body({0.01, 0.01, 0.01}, world);
  CHECK_FALSE(world.penetration(cube, at(0, 0.01, 0)));           // resting on the floor
  CHECK_FALSE(world.penetration(cube, at(0, 0.0099, 0)));         // 0.1 mm in: within tolerance
  const auto hit = world.penetration(cube, at(0, 0.009, 0));      // 1 mm in
  REQUIRE(hit);
  CHECK(hit->body_name == "floor");
  CHECK(hit->member == "part");
  CHECK(hit->depth == Approx(0.001).margin(2e-4));
}

TEST_CASE("a sweep finds the first collision along the way, not only at its ends", "[collision]") {
  sim::CollisionWorld world;
  world.add_static_box("wall", {0.005, 0.05, 0.05}, at(0, 0, 0));
  const auto cube = box_body({0.01, 0.01, 0.01}, world);
  const auto hit = world.sweep(cube, at(-0.2, 0, 0), at(0.2, 0, 0));
  REQUIRE(hit);
  CHECK(hit->body_name == "wall");
  CHECK(hit->fraction == Approx(0.5 - 0.015 / 0.4).margin(0.01));
  CHECK_FALSE(world.sweep(cube, at(-0.2, 0.2, 0), at(0.2, 0.2, 0)));  // passes above it
}

TEST_CASE("a turning body is checked along its rotation", "[collision]") {
  sim::CollisionWorld world;
  world.add_static_box("post", {0.005, 0.05, 0.005}, at(0.05, 0, -0.05));  // at 45 degrees of the turn
  sim::MovingBody bar;
  bar.add_box("part", {0.08, 0.005, 0.005}, sim::Pose::Identity(), world.options().shape_margin);
  const sim::Pose start = sim::Pose::Identity();
  sim::Pose turned = sim::Pose::Identity();
  turned.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  CHECK_FALSE(world.penetration(bar, start));
  CHECK_FALSE(world.penetration(bar, turned));
  CHECK(world.sweep(bar, start, turned));  // sweeps through the post at 45 degrees
}

TEST_CASE("Cranfield: a peg passes down through its hole, and 1 mm to the side it collides", "[collision][cranfield]") {
  sim::MeshCache meshes;
  sim::CollisionWorld world;
  world.add_static_mesh("back", meshes.get(products("cranfield/meshes/faceplate.obj")), at(0, 0, 0));
  for (const char* mesh : {"square_peg.obj", "round_peg.obj"}) {
    INFO(mesh);
    sim::MovingBody peg;
    peg.add_mesh("part", *meshes.get(products(std::string("cranfield/meshes/") + mesh)), sim::Pose::Identity(),
                 world.options().shape_margin);
    // The square_left hole for the square peg, the shaft hole for the round one.
    const double hx = std::string(mesh) == "square_peg.obj" ? -0.040 : 0.0;
    const double hz = std::string(mesh) == "square_peg.obj" ? 0.069 : 0.014;
    CHECK_FALSE(world.sweep(peg, at(hx, 0.2, hz), at(hx, 0, hz)));
    const auto hit = world.sweep(peg, at(hx + 0.001, 0.2, hz), at(hx + 0.001, 0, hz));
    REQUIRE(hit);
    CHECK(hit->body_name == "back");
    CHECK(hit->depth > world.options().contact_tolerance);
  }
}

TEST_CASE("Lego: a brick slides onto a brick and sits on it", "[collision][lego]") {
  sim::MeshCache meshes;
  sim::CollisionWorld world;
  const auto brick = meshes.get(products("lego-tower/meshes/brick_2x4.obj"));
  world.add_static_mesh("below", brick, at(0, 0, 0));
  sim::MovingBody moving;
  moving.add_mesh("part", *meshes.get(products("lego-tower/meshes/brick_2x2.obj")), sim::Pose::Identity(),
                  world.options().shape_margin);
  CHECK_FALSE(world.sweep(moving, at(0.1, 0.0096, 0), at(0.004, 0.0096, 0)));  // slides along the top
  CHECK_FALSE(world.sweep(moving, at(0.004, 0.1, 0), at(0.004, 0.0096, 0)));   // comes down onto it
  CHECK(world.sweep(moving, at(0.1, 0.0090, 0), at(0.004, 0.0090, 0)));        // 0.6 mm too low
}
