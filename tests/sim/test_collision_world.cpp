#include <unistd.h>

#include <cstring>
#include <limits>

#include <catch2/catch.hpp>

#include "sim/collision/collision_world.hpp"
#include "sim/mesh/mesh_disk_cache.hpp"
#include "sim/mesh/triangle_bvh.hpp"
#include "tests/support/meshes.hpp"
#include "tests/support/paths.hpp"

namespace {

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
  world.add_static_mesh("back", meshes.get(test::product("cranfield/meshes/faceplate.obj")), at(0, 0, 0));
  for (const char* mesh : {"square_peg.obj", "round_peg.obj"}) {
    INFO(mesh);
    sim::MovingBody peg;
    peg.add_mesh("part", *meshes.get(test::product(std::string("cranfield/meshes/") + mesh)), sim::Pose::Identity(),
                 world.options().shape_margin);
    // The square_left hole for the square peg, the shaft hole for the round one.
    const double hx = std::string(mesh) == "square_peg.obj" ? -0.040 : 0.0;
    const double hz = std::string(mesh) == "square_peg.obj" ? 0.069 : 0.014;
    const std::size_t before = world.checks();
    CHECK_FALSE(world.sweep(peg, at(hx, 0.2, hz), at(hx, 0, hz)));
    // Its swept volume down the hole is clear: one check, not a sample a millimetre apart
    // wherever the peg is near the plate (16 of them).
    CHECK(world.checks() - before <= 2);
    const auto hit = world.sweep(peg, at(hx + 0.001, 0.2, hz), at(hx + 0.001, 0, hz));
    REQUIRE(hit);
    CHECK(hit->body_name == "back");
    CHECK(hit->depth > world.options().contact_tolerance);
  }
}

TEST_CASE("Lego: a brick slides onto a brick and sits on it", "[collision][lego]") {
  sim::MeshCache meshes;
  sim::CollisionWorld world;
  const auto brick = meshes.get(test::product("lego-tower/meshes/brick_2x4.obj"));
  world.add_static_mesh("below", brick, at(0, 0, 0));
  sim::MovingBody moving;
  moving.add_mesh("part", *meshes.get(test::product("lego-tower/meshes/brick_2x2.obj")), sim::Pose::Identity(),
                  world.options().shape_margin);
  CHECK_FALSE(world.sweep(moving, at(0.1, 0.0096, 0), at(0.004, 0.0096, 0)));  // slides along the top
  CHECK_FALSE(world.sweep(moving, at(0.004, 0.1, 0), at(0.004, 0.0096, 0)));   // comes down onto it
  CHECK(world.sweep(moving, at(0.1, 0.0090, 0), at(0.004, 0.0090, 0)));        // 0.6 mm too low
}

TEST_CASE("a one-piece concave part that moves is checked by its triangles, not by its hull", "[collision][exact]") {
  sim::CollisionWorld world;  // contact tolerance 0.3 mm
  const double hole = 0.010;  // a 20 mm square hole in the frame
  sim::MovingBody frame;
  frame.add_mesh("part", test::one_piece_frame(hole, 0.010, 0.010), sim::Pose::Identity(), world.options().shape_margin);

  SECTION("a 0.2 mm clearance fit goes over the post, down its whole length") {
    world.add_static_box("post", {hole - 0.0002, 0.05, hole - 0.0002}, at(0, 0, 0));
    CHECK_FALSE(world.penetration(frame, at(0, 0, 0)));
    CHECK_FALSE(world.sweep(frame, at(0, 0.1, 0), at(0, -0.03, 0)));
    const auto aside = world.penetration(frame, at(0.001, 0, 0));  // 1 mm to the side: 0.8 mm into the post
    REQUIRE(aside);
    CHECK(aside->body_name == "post");
    CHECK(aside->member == "part");
    CHECK(aside->depth == Approx(0.0008).margin(2e-4));
  }
  SECTION("a 0.4 mm interference is caught, with its depth") {
    world.add_static_box("post", {hole + 0.0004, 0.05, hole + 0.0004}, at(0, 0, 0));
    const auto hit = world.penetration(frame, at(0, 0, 0));
    REQUIRE(hit);
    CHECK(hit->depth == Approx(0.0004).margin(1.5e-4));
    const auto swept = world.sweep(frame, at(0, 0.1, 0), at(0, -0.03, 0));
    REQUIRE(swept);
    CHECK(swept->body_name == "post");
  }
  SECTION("against a one-piece concave static part too: the frame slides into a frame's opening") {
    // A bigger frame lies flat; the small one goes down through its 40 mm hole with 1 mm
    // to spare on every side and would hit it 2 mm off to the side.
    auto big = std::make_shared<sim::TriangleMesh>(test::one_piece_frame(0.021, 0.010, 0.010));
    world.add_static_mesh("big frame", big, at(0, 0, 0));
    CHECK_FALSE(world.sweep(frame, at(0, 0.1, 0), at(0, -0.1, 0)));
    CHECK(world.sweep(frame, at(0.002, 0.1, 0), at(0.002, -0.1, 0)));
  }
}

TEST_CASE("a concave ring set into a concave ring is caught by volume, however fine its triangles, and one resting on it is not",
          "[collision][exact]") {
  // Triangle against triangle, the way out of two crossing thin triangles is short: a ring
  // 4 mm into another (each 5 mm tall) came out clear at 1 000 triangles and at 50 000.
  for (const int segments : {125, 1250}) {
    INFO(segments * 8 << " triangles per ring");
    sim::CollisionWorld world;
    world.add_static_mesh("ring below", std::make_shared<sim::TriangleMesh>(test::tube_mesh(segments, 0.020, 0.010, 0.005)),
                          at(0, 0, 0));
    sim::MovingBody ring;
    ring.add_mesh("part", test::tube_mesh(segments, 0.02001, 0.010, 0.005), sim::Pose::Identity(),
                  world.options().shape_margin);
    CHECK_FALSE(world.penetration(ring, at(0, 0.005, 0)));  // resting on it
    for (const double into : {0.0004, 0.002}) {
      INFO(into * 1000 << " mm into it");
      const auto hit = world.penetration(ring, at(0, 0.005 - into, 0));
      REQUIRE(hit);
      CHECK(hit->body_name == "ring below");
      CHECK(hit->member == "part");
      CHECK(hit->depth > world.options().contact_tolerance);
      CHECK(hit->depth <= into + 1e-4);
    }
    const auto beside = world.penetration(ring, at(0.039, 0.0, 0));  // 1 mm into its side
    REQUIRE(beside);
    CHECK(beside->depth > world.options().contact_tolerance);  // a least depth: the first point found past it
    CHECK(beside->depth <= 0.001 + 1e-4);
    CHECK_FALSE(world.penetration(ring, at(0.0402, 0.0, 0)));  // 0.2 mm beside it
  }
}

TEST_CASE("a concave ring resting on one concave part and set into another is caught in the second",
          "[collision][exact]") {
  // The ring's triangles that rest on the part below are asked by volume against it; that
  // must not keep them from being asked against the wide ring that they also go 0.4 mm into,
  // whose own corners and middles all lie outside the ring (and triangle against triangle
  // lets two thin crossing triangles go).
  const auto joined = [](sim::TriangleMesh a, const sim::TriangleMesh& b) {  // one piece
    const auto offset = static_cast<std::uint32_t>(a.vertices.size());
    for (const auto& v : b.vertices) {
      a.pieces.back().push_back(static_cast<std::uint32_t>(a.vertices.size()));
      a.vertices.push_back(v);
      a.bounds.extend(v);
    }
    for (const auto& t : b.triangles) a.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    return a;
  };
  // A ring with a pin standing in the moving ring's bore, 6 mm clear of it: its hull is hit.
  auto below = std::make_shared<sim::TriangleMesh>(
      joined(test::tube_mesh(1250, 0.020, 0.010, 0.005), test::tube_mesh(64, 0.004, 0, 0.008)));
  auto wide = std::make_shared<sim::TriangleMesh>(test::tube_mesh(1250, 0.060, 0.005, 0.005));
  sim::CollisionWorld world;
  const auto add_below = [&] { world.add_static_mesh("ring below", below, sim::Pose::Identity()); };
  const auto add_wide = [&] { world.add_static_mesh("wide ring", wide, at(0, 0.0004, 0)); };  // its top 0.4 mm higher
  SECTION("the ring below asked first") {
    add_below();
    add_wide();
  }
  SECTION("the wide ring asked first") {
    add_wide();
    add_below();
  }
  sim::MovingBody ring;
  ring.add_mesh("ring", test::tube_mesh(1250, 0.02001, 0.010, 0.005), sim::Pose::Identity(), world.options().shape_margin);
  const auto hit = world.penetration(ring, at(0, 0.005, 0));  // resting on the ring below
  REQUIRE(hit);
  CHECK(hit->body_name == "wide ring");
  CHECK(hit->depth > world.options().contact_tolerance);
  CHECK(hit->depth <= 0.0004 + 1e-4);
  CHECK_FALSE(world.penetration(ring, at(0, 0.0054, 0)));  // on the wide ring, clear of the other
}

TEST_CASE("a concave ring over a concave ring is nearest where it comes nearest, held flat or tilted",
          "[collision][exact]") {
  // Pairs of triangles whose boxes lie as far apart as the nearest pair so far are not asked:
  // this checks that no nearer pair is left out with them.
  for (const int segments : {100, 1000}) {  // even: a corner lies at 180 degrees, where the tilt is lowest
    INFO(segments * 8 << " triangles per ring");
    sim::CollisionWorld world;
    world.add_static_mesh("ring below", std::make_shared<sim::TriangleMesh>(test::tube_mesh(segments, 0.020, 0.010, 0.005)),
                          at(0, 0, 0));
    sim::MovingBody ring;
    ring.add_mesh("part", test::tube_mesh(segments, 0.020, 0.010, 0.005), sim::Pose::Identity(), world.options().shape_margin);
    const auto flat = world.nearest(ring, at(0, 0.006, 0), 0.01);
    REQUIRE(flat);
    CHECK(flat->distance == Approx(0.001).margin(1e-6));
    const double tilt = 2 * M_PI / 180;
    sim::Pose tilted = at(0, 0.008, 0);
    tilted.linear() = Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const auto near = world.nearest(ring, tilted, 0.01);
    REQUIRE(near);
    CHECK(near->distance == Approx(0.003 - 0.020 * std::sin(tilt)).margin(1e-6));  // its rim at -x
  }
}

TEST_CASE("a convex pin of many corners is checked by a hull of few, at most 0.01 mm larger, moving or standing",
          "[collision][exact]") {
  const auto ring = std::make_shared<sim::TriangleMesh>(test::tube_mesh(1250, 0.020, 0.010, 0.005));
  for (const double radius : {0.0098, 0.0104}) {  // a 0.2 mm clearance fit, a 0.4 mm interference
    INFO("pin " << radius * 2000 << " mm across");
    sim::TriangleMesh pin = test::tube_mesh(6000, radius, 0, 0.005);  // 36 000 triangles
    pin.convex = sim::is_convex(pin);  // and the rest of what loading finds
    pin.hull_corners = sim::hull_corners(pin);
    sim::make_coarse_hull(pin);
    REQUIRE(pin.convex);
    REQUIRE(sim::hull_simplified(pin));
    CHECK(pin.coarse_corners.size() == sim::kCoarseCorners);
    CHECK(pin.coarse_margin <= sim::kSimplifiedHullGrowth);
    CHECK_THAT(sim::loading_report(pin),
               Catch::Contains("its collision hull simplified from ") && Catch::Contains(" to 256 corners, at most 0.0"));
    sim::TriangleMesh exact_pin = pin;
    exact_pin.coarse_corners.clear();
    exact_pin.coarse_margin = 0;
    CHECK(sim::loading_report(exact_pin).empty());

    sim::CollisionWorld world;
    world.add_static_mesh("ring", ring, sim::Pose::Identity());
    const auto depth_of = [&](const sim::TriangleMesh& mesh) {
      sim::MovingBody body;
      body.add_mesh("pin", mesh, sim::Pose::Identity(), world.options().shape_margin);
      const auto hit = world.penetration(body, sim::Pose::Identity());
      return hit ? hit->depth : 0.0;
    };
    const double simplified = depth_of(pin), exact = depth_of(exact_pin);
    if (radius < 0.010) {
      CHECK(simplified == 0);
      CHECK(exact == 0);
    } else {
      CHECK(exact == Approx(0.0005).margin(1e-4));  // 0.4 mm and the two shapes' margins
      CHECK(simplified >= exact);  // the simplified hull only grows
      CHECK(simplified <= exact + sim::kSimplifiedHullGrowth);
    }
    // Its room to a wall 0.2 mm beside it, turned so that the wall faces the simplified hull's
    // corners or the edges between them: never more than the exact pin's, at most the growth less.
    sim::CollisionWorld beside;
    beside.add_static_box("wall", {0.005, 0.01, 0.02}, at(radius + 0.0002 + 0.005, 0, 0));
    for (int step = 0; step < 8; ++step) {
      sim::Pose turned = sim::Pose::Identity();
      turned.linear() = Eigen::AngleAxisd(step * 0.4 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
      const auto room_of = [&](const sim::TriangleMesh& mesh) {
        sim::MovingBody body;
        body.add_mesh("pin", mesh, sim::Pose::Identity(), beside.options().shape_margin);
        const auto near = beside.nearest(body, turned, 0.001);
        return near ? near->distance : 1.0;
      };
      INFO("turned by " << step * 0.4 << " degrees");
      const double room = room_of(pin), exact_room = room_of(exact_pin);
      CHECK(exact_room == Approx(0.0002).margin(1e-6));
      CHECK(room <= exact_room + 1e-9);
      CHECK(room >= exact_room - sim::kSimplifiedHullGrowth);
    }
    // The pin standing, the ring coming down onto it.
    sim::CollisionWorld standing;
    standing.add_static_mesh("pin", std::make_shared<sim::TriangleMesh>(pin), sim::Pose::Identity());
    sim::MovingBody coming;
    coming.add_mesh("ring", ring, sim::Pose::Identity(), standing.options().shape_margin);
    CHECK(bool(standing.penetration(coming, sim::Pose::Identity())) == (radius > 0.010));
  }
}

TEST_CASE("clearance: how near a body comes, box to box, peg to hole and frame to post", "[collision][margin]") {
  sim::CollisionWorld world;
  world.add_static_box("wall", {0.005, 0.05, 0.05}, at(0, 0, 0));
  const auto cube = box_body({0.01, 0.01, 0.01}, world);
  // 5 mm between the cube's face and the wall's.
  const auto near = world.nearest(cube, at(-0.02, 0, 0), 0.01);
  REQUIRE(near);
  CHECK(near->body_name == "wall");
  CHECK(near->member == "part");
  CHECK(near->distance == Approx(0.005).margin(1e-5));
  CHECK(near->normal.x() == Approx(-1).margin(1e-3));  // from the wall towards the cube
  CHECK_FALSE(world.nearest(cube, at(-0.03, 0, 0), 0.01));  // 15 mm: beyond the reach
  // A filter leaves the pair out.
  CHECK_FALSE(world.nearest(cube, at(-0.02, 0, 0), 0.01, [](const sim::Clearance&) { return false; }));
  // Along a move towards the wall and past it above: the nearest is 2 mm, at the end.
  const auto along = world.nearest_along(cube, at(-0.2, 0, 0), at(-0.017, 0, 0), 0.01);
  REQUIRE(along);
  CHECK(along->distance == Approx(0.002).margin(1e-5));
  const auto over = world.nearest_along(cube, at(-0.2, 0.063, 0), at(0.2, 0.063, 0), 0.01);
  REQUIRE(over);
  CHECK(over->distance == Approx(0.003).margin(1e-5));  // 3 mm above the wall's top
  // Turning a quarter on the way, it ends as it would without: 2 mm (measured pose by pose).
  sim::Pose turned = at(-0.017, 0, 0);
  turned.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const auto turning = world.nearest_along(cube, at(-0.2, 0, 0), turned, 0.01);
  REQUIRE(turning);
  CHECK(turning->distance == Approx(0.002).margin(1e-5));
  SECTION("a round peg in its hole in Cranfield's plate: the play around it") {
    sim::MeshCache meshes;
    sim::CollisionWorld plate;
    plate.add_static_mesh("back", meshes.get(test::product("cranfield/meshes/faceplate.obj")), at(0, 0, 0));
    sim::MovingBody peg;
    peg.add_mesh("part", *meshes.get(test::product("cranfield/meshes/round_peg.obj")), sim::Pose::Identity(),
                 plate.options().shape_margin);
    const auto in_hole = plate.nearest(peg, at(0, 0.005, 0.014), 0.01);
    REQUIRE(in_hole);
    INFO("play " << in_hole->distance * 1000 << " mm");
    CHECK(in_hole->distance < 0.002);
    const auto aside = plate.nearest(peg, at(0.0005, 0.005, 0.014), 0.01);  // 0.5 mm to one side
    REQUIRE(aside);
    CHECK(aside->distance < in_hole->distance);
  }
  SECTION("a one-piece concave frame around a post, 0.2 mm on every side, measured by its triangles") {
    sim::CollisionWorld posts;
    posts.add_static_box("post", {0.0098, 0.05, 0.0098}, at(0, 0, 0));
    sim::MovingBody frame;
    frame.add_mesh("part", test::one_piece_frame(0.010, 0.010, 0.010), sim::Pose::Identity(),
                   posts.options().shape_margin);
    const auto c = posts.nearest(frame, at(0, 0, 0), 0.01);
    REQUIRE(c);
    CHECK(c->distance == Approx(0.0002).margin(6e-5));
  }
}

TEST_CASE("clearance along a move without turning is its least, between samples too", "[collision][margin]") {
  sim::CollisionWorld world;
  world.add_static_box("wall", {0.005, 0.05, 0.05}, at(0, 0, 0));
  const auto cube = box_body({0.01, 0.01, 0.01}, world);
  // The cube's lower edge passes the wall's upper edge diagonally, nearest (0.2 mm) at t = 0,
  // which lies between two of the 0.58 mm samples the move would be cut into: sampled, the
  // least was 0.29 mm. Box corners are rounded by their margin (0.05 mm): 0.22 mm.
  const Eigen::Vector3d edge(-0.005, 0.05, 0);
  const Eigen::Vector3d across = Eigen::Vector3d(-1, 1, 0).normalized(), along = Eigen::Vector3d(1, 1, 0).normalized();
  const auto centre = [&](double t) {
    const Eigen::Vector3d c = edge + 0.0002 * across + t * along - Eigen::Vector3d(0.01, -0.01, 0);
    return at(c.x(), c.y(), c.z());
  };
  const auto past = world.nearest_along(cube, centre(-0.020), centre(0.0173), 0.01);
  REQUIRE(past);
  INFO("least " << past->distance * 1000 << " mm");
  CHECK(past->distance == Approx(0.0002).margin(3e-5));
}

TEST_CASE("clearance of a closing member leaves out what lies beyond the end of its move", "[collision][margin]") {
  sim::CollisionWorld world;
  world.add_static_box("floor", {0.1, 0.01, 0.1}, at(0, -0.01, 0));
  const auto cube = box_body({0.01, 0.01, 0.01}, world);
  // Lowered to 1 mm above the floor: head-on, the floor is the nearest.
  const auto down = world.nearest_along(cube, at(0, 0.05, 0), at(0, 0.011, 0), 0.01);
  REQUIRE(down);
  CHECK(down->body_name == "floor");
  CHECK(down->distance == Approx(0.001).margin(1e-5));
  // The part closes on it: it never comes beside the floor, which is not asked.
  CHECK_FALSE(world.nearest_along(cube, at(0, 0.05, 0), at(0, 0.011, 0), 0.01, {}, "part"));
  CHECK(world.nearest_along(cube, at(0, 0.05, 0), at(0, 0.011, 0), 0.01, {}, "finger"));  // another member's
  // A post beside the way down, 0.5 mm from the cube's side, is beside it.
  world.add_static_box("post", {0.005, 0.02, 0.005}, at(0.0155, 0.02, 0));
  const auto beside = world.nearest_along(cube, at(0, 0.05, 0), at(0, 0.011, 0), 0.01, {}, "part");
  REQUIRE(beside);
  CHECK(beside->body_name == "post");
  CHECK(beside->distance == Approx(0.0005).margin(1e-5));
}

TEST_CASE("a concave mesh's triangle tree is made at loading, kept by the disk cache, and used only where it is whole",
          "[collision][mesh][cache]") {
  const auto folder = std::filesystem::temp_directory_path() / ("bvh-cache-" + std::to_string(::getpid()));
  std::filesystem::remove_all(folder);
  const auto file = std::filesystem::path(TEST_DATA_DIR) / "planning/shaft-bearing/meshes/bearing.obj";
  const auto loaded = sim::MeshCache(folder).get(file, 1e-3);
  REQUIRE_FALSE(sim::pieces_are_exact(*loaded));
  const std::size_t node_size = 16, nodes = 2 * loaded->triangles.size() - 1;  // a leaf per triangle
  CHECK(loaded->bvh_nodes.size() == nodes * node_size);
  const auto cached = sim::MeshDiskCache(folder).load(file, 1e-3);
  CHECK(cached->bvh_nodes == loaded->bvh_nodes);
  const double margin = sim::CollisionOptions{}.shape_margin;
  CHECK(sim::StaticMeshShape(*cached, margin).tree_was_kept());
  std::filesystem::remove_all(folder);

  // A damaged tree (a leaf naming a triangle the mesh does not have, a skip out of the tree,
  // nodes missing) is built anew; so is none.
  const auto leaf = [&](bool want_leaf) {
    for (std::size_t i = 0; i < nodes; ++i) {
      std::int32_t v = 0;
      std::memcpy(&v, loaded->bvh_nodes.data() + i * node_size + 12, sizeof v);
      if ((v >= 0) == want_leaf) return i;
    }
    return nodes;
  };
  const auto with_node = [&](std::size_t at, std::int32_t value) {
    auto m = std::make_shared<sim::TriangleMesh>(*loaded);
    std::memcpy(m->bvh_nodes.data() + at * node_size + 12, &value, sizeof value);
    return m;
  };
  CHECK_FALSE(sim::StaticMeshShape(*with_node(leaf(true), static_cast<std::int32_t>(loaded->triangles.size())), margin)
                  .tree_was_kept());
  CHECK_FALSE(sim::StaticMeshShape(*with_node(leaf(false), -static_cast<std::int32_t>(nodes) - 1), margin).tree_was_kept());
  CHECK_FALSE(sim::StaticMeshShape(*with_node(leaf(false), std::numeric_limits<std::int32_t>::min()), margin).tree_was_kept());
  auto none = std::make_shared<sim::TriangleMesh>(*loaded);
  none->bvh_nodes.resize(node_size * (nodes - 1));
  CHECK_FALSE(sim::StaticMeshShape(*none, margin).tree_was_kept());
  none->bvh_nodes.clear();
  CHECK_FALSE(sim::StaticMeshShape(*none, margin).tree_was_kept());

  // The kept tree answers as one built anew: a 2 mm cube probed around and through the bearing.
  sim::CollisionWorld kept_world, built_world;
  kept_world.add_static_mesh("bearing", loaded, sim::Pose::Identity());
  built_world.add_static_mesh("bearing", none, sim::Pose::Identity());
  const auto cube = box_body({0.001, 0.001, 0.001}, kept_world);
  const Eigen::AlignedBox3d box = loaded->bounds;
  int hits = 0, misses = 0;
  for (int i = 0; i <= 8; ++i) {
    for (int j = 0; j <= 8; ++j) {
      for (int k = 0; k <= 8; ++k) {
        const Eigen::Vector3d p = box.min() + (box.max() - box.min()).cwiseProduct(Eigen::Vector3d(i, j, k) / 8.0);
        const auto kept = kept_world.penetration(cube, at(p.x(), p.y(), p.z()));
        const auto built = built_world.penetration(cube, at(p.x(), p.y(), p.z()));
        REQUIRE(kept.has_value() == built.has_value());
        if (kept) CHECK(kept->depth == Approx(built->depth).margin(1e-9));
        ++(kept ? hits : misses);
      }
    }
  }
  CHECK(hits > 50);
  CHECK(misses > 50);
}

TEST_CASE("a concave part crossing a concave part between its triangles' corners is caught", "[collision][concave]") {
  // Two U channels of one piece each, 200 mm long, their long faces two triangles from end to
  // end, crossed at right angles: the upper one's base 1 mm down into the lower one's walls.
  // No corner and no middle of any triangle lies in the other channel (the crossing is in the
  // middle, the corners at the ends, the middles a third of the way), so points of the
  // triangles chosen in advance would not tell; the volume stage searches whole triangles
  // (sim::deepest_inside).
  sim::CollisionWorld world;
  const auto lower = std::make_shared<sim::TriangleMesh>(test::u_channel(0.2, 0.02, 0.02, 0.004));
  world.add_static_mesh("lower", lower, sim::Pose::Identity());
  sim::MovingBody upper;
  upper.add_mesh("part", test::u_channel(0.2, 0.02, 0.02, 0.004), sim::Pose::Identity(), world.options().shape_margin);
  sim::Pose crossed = at(0, 0.019, 0);  // its base's underside 1 mm below the walls' tops
  crossed.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const auto hit = world.penetration(upper, crossed);
  REQUIRE(hit);
  CHECK(hit->body_name == "lower");
  CHECK(hit->depth > world.options().contact_tolerance);
  // Resting on the walls: clear.
  crossed.translation().y() = 0.020;
  CHECK_FALSE(world.penetration(upper, crossed));
}
