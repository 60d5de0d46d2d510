// The dashboard's physical scene (deploy/cellctl/physical_scene.hpp) from cell-sim's requests
// and replies: a move runs at cell-sim's pace and carries what it carries, its reply sets
// when it began, where a collision stopped it, or undoes a refused one; virtual bodies and
// hostile requests are left out.

#include <cmath>
#include <limits>

#include <catch2/catch.hpp>

#include "deploy/cellctl/physical_scene.hpp"

namespace {

cell::Pose pose(double x, double y, double z) {
  cell::Pose p;
  p.position().x(x);
  p.position().y(y);
  p.position().z(z);
  p.qw(1);
  return p;
}

cell::SimRequest spawn(const std::string& body, const std::string& requester, const std::string& order, cell::Pose at,
                       const std::string& scene = "") {
  cell::SimRequest r;
  r.request_id(requester + "/" + body);
  r.kind("spawn");
  r.body_id(body);
  r.requester(requester);
  r.order_id(order);
  r.placement(at);
  r.scene(scene);
  if (requester.rfind("o", 0) == 0) r.mesh_uri("/parts/" + body + ".stl");
  return r;
}

cell::SimRequest move(const std::string& id, const std::string& body, std::vector<cell::Pose> path, double speed,
                      std::vector<std::string> carried = {}) {
  cell::SimRequest r;
  r.request_id(id);
  r.kind("move");
  r.body_id(body);
  r.requester("mobile-robot-1");
  r.path(path);
  r.speed(speed);
  for (const auto& c : carried) r.carried().push_back(c);
  return r;
}

cell::SimReply reply(const std::string& id, bool ok, double start, double end, bool collided = false) {
  cell::SimReply r;
  r.request_id(id);
  r.ok(ok);
  r.start_time(start);
  r.end_time(end);
  r.collided(collided);
  return r;
}

nlohmann::json body_of(const cellctl::PhysicalScene& scene, const std::string& id, double now) {
  for (const auto& b : scene.bodies(now)) {
    if (b["id"] == id) return b;
  }
  return nullptr;
}

}  // namespace

TEST_CASE("a robot's drive runs at its speed with the part it carries, from when cell-sim began it",
          "[cellctl][dashboard]") {
  cellctl::PhysicalScene scene;
  scene.take(spawn("mobile-robot-1/base", "mobile-robot-1", "", pose(0, 0, 0)), 0);
  scene.take(spawn("o1/brick", "o1", "", pose(0, 0.3, 0)), 0);  // as a twin spawns its parts
  scene.take(spawn("o1/virtual/brick", "o1", "o1", pose(5, 5, 5), "o1/virtual"), 0);
  CHECK(scene.size() == 2);  // the virtual scene's body is not the cell's
  const auto base = body_of(scene, "mobile-robot-1/base", 0);
  CHECK(base["owner"] == "mobile-robot-1");
  CHECK(base["mesh"] == false);
  CHECK(body_of(scene, "o1/brick", 0)["owner"] == "");
  CHECK(body_of(scene, "o1/brick", 0)["order"] == "o1");
  CHECK(body_of(scene, "o1/brick", 0)["mesh"] == true);

  // 2 m at 0.5 m/s, then 1 m: heard at sim 10 s.
  scene.take(move("m1", "mobile-robot-1/base", {pose(2, 0, 0), pose(2, 0, 1)}, 0.5, {"o1/brick"}), 10);
  auto moving = body_of(scene, "mobile-robot-1/base", 11);
  REQUIRE(moving.contains("motion"));
  CHECK(moving["motion"]["t"] == nlohmann::json({10.0, 14.0, 16.0}));
  CHECK(moving["pose"] == nlohmann::json({2.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0}));  // where it ends
  auto carried = body_of(scene, "o1/brick", 11);
  REQUIRE(carried.contains("motion"));
  CHECK(carried["motion"]["poses"][1] == nlohmann::json({2.0, 0.3, 0.0, 1.0, 0.0, 0.0, 0.0}));
  CHECK(carried["pose"] == nlohmann::json({2.0, 0.3, 1.0, 1.0, 0.0, 0.0, 0.0}));

  // cell-sim began it at 10.5 s: its reply comes at the end.
  scene.take(reply("m1", true, 10.5, 16.5));
  CHECK(body_of(scene, "o1/brick", 11)["motion"]["t"] == nlohmann::json({10.5, 14.5, 16.5}));
  CHECK_FALSE(body_of(scene, "mobile-robot-1/base", 17).contains("motion"));  // over

  scene.take(spawn("o1/brick", "o1", "o1", pose(0, 0, 0)), 20);
  scene.take([] {
    cell::SimRequest r;
    r.kind("remove");
    r.body_id("o1/brick");
    return r;
  }(), 21);
  CHECK(scene.size() == 1);
}

TEST_CASE("a resource's body whose spawn was not heard is taken in by its first move", "[cellctl][dashboard]") {
  cellctl::PhysicalScene scene({"mobile-robot-1"});
  scene.take(move("m1", "mobile-robot-1/base", {pose(2, 0, 0), pose(2, 0, 1)}, 0.5), 10);  // requester mobile-robot-1
  const auto base = body_of(scene, "mobile-robot-1/base", 11);
  REQUIRE(base.is_object());
  CHECK(base["owner"] == "mobile-robot-1");
  CHECK(base["motion"]["t"] == nlohmann::json({10.0, 10.0, 12.0}));
  auto stranger = move("m2", "o1/virtual/brick", {pose(1, 0, 0)}, 1);
  stranger.requester("o1");  // a twin's virtual body
  scene.take(stranger, 10);
  CHECK(scene.size() == 1);
}

TEST_CASE("a move that collides stops where it hit, and one cell-sim refused did not happen", "[cellctl][dashboard]") {
  cellctl::PhysicalScene scene;
  scene.take(spawn("arm-1/palm", "arm-1", "", pose(0, 1, 0)), 0);
  scene.take(move("m1", "arm-1/palm", {pose(0, 0, 0)}, 0.1), 0);  // 10 s down
  scene.take(reply("m1", true, 0, 4, true));  // hit something after 0.4 m
  const auto hit = body_of(scene, "arm-1/palm", 1);
  CHECK(hit["pose"][1].get<double>() == Approx(0.6));
  CHECK(hit["motion"]["t"].back() == 4.0);

  scene.take(move("m2", "arm-1/palm", {pose(3, 3, 3)}, 1), 5);
  CHECK(body_of(scene, "arm-1/palm", 5)["pose"][0] == 3.0);
  scene.take(reply("m2", false, 5, 5));
  const auto refused = body_of(scene, "arm-1/palm", 5);
  CHECK(refused["pose"][1].get<double>() == Approx(0.6));
  CHECK_FALSE(refused.contains("motion"));
}

TEST_CASE("the physical scene leaves out what it cannot draw: bad poses, strangers' moves, bodies past its bound",
          "[cellctl][dashboard]") {
  cellctl::PhysicalScene scene;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  scene.take(spawn("a", "arm-1", "", pose(nan, 0, 0)), 0);
  cell::Pose zero = pose(0, 0, 0);
  zero.qw(0);
  scene.take(spawn("b", "arm-1", "", zero), 0);
  CHECK(scene.size() == 0);

  scene.take(spawn("c", "arm-1", "", pose(0, 0, 0)), 0);
  scene.take(move("m1", "nobody", {pose(1, 0, 0)}, 1), 0);  // by a requester that is no resource of the cell
  scene.take(move("m2", "c", {pose(1, 0, 0)}, 0), 0);                     // no speed
  scene.take(move("m3", "c", {pose(1, 0, 0), pose(1, nan, 0)}, 1), 0);    // a bad waypoint
  scene.take(move("m4", "c", {pose(1, std::numeric_limits<double>::infinity(), 0)}, 1), 0);
  CHECK(body_of(scene, "c", 0)["pose"][0] == 0.0);
  scene.take(reply("unknown", true, 0, 1));

  for (std::size_t i = 0; i < cellctl::PhysicalScene::kMaxBodies + 10; ++i) {
    scene.take(spawn("p" + std::to_string(i), "o1", "o1", pose(0, 0, 0)), 0);
  }
  CHECK(scene.size() == cellctl::PhysicalScene::kMaxBodies);
}
