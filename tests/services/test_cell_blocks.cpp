// The cell's device blocks and cell-sim's world, driven with events and no DDS.

#include <catch2/catch.hpp>

#include "services/mobile_robot/mobile_robot_block.hpp"
#include "services/runtime/block_test_fixture.hpp"
#include "services/station/arm_block.hpp"
#include "sim/cell_sim/world_block.hpp"
#include "sim/world/sim_world.hpp"

namespace {

using Names = std::vector<std::string>;
template <class B>
Names names(const std::vector<fb::Event>& events) {
  return fb::BlockTestFixture<B>::names(events);
}

fb::Data command(const std::string& id, const std::string& operation, fb::Data extra = {}) {
  extra["command_id"] = id;
  extra["resource_id"] = std::string("arm-1");
  extra["operation"] = operation;
  return extra;
}

fb::Data reply_to(const fb::Event& request, fb::Data extra = {}) {
  extra["request_id"] = request.data.at("request_id");
  extra["ok"] = true;
  return extra;
}

}  // namespace

TEST_CASE("arm: a grip places pad and carriage, a second grip replaces them", "[fb][arm]") {
  fb::BlockTestFixture<fb::ArmBlock> f("arm", "arm-1", fb::ArmSettings{});
  const fb::Data grasp{{"part", std::string("o1/B1")}, {"path", fb::Numbers{0, 0.1, 0, 1, 0, 0, 0}},
                       {"size", fb::Numbers{0.01, 0.005, 0.01}}, {"direction", fb::Numbers{0, -1, 0}}};
  for (int round = 0; round < 2; ++round) {
    const std::string id = "g" + std::to_string(round);
    CHECK(names<fb::ArmBlock>(f.send("COMMAND", command(id, "grip", grasp))) == Names{"ACCEPT"});
    const auto requests = f.send("START", {{"command_id", id}});
    REQUIRE(requests.size() == (round == 0 ? 2u : 4u));
    for (std::size_t i = 0; i + 1 < requests.size(); ++i) CHECK(f.send("SIM_REPLY", reply_to(requests[i])).empty());
    CHECK(names<fb::ArmBlock>(f.send("SIM_REPLY", reply_to(requests.back()))) == Names{"DONE"});
  }
  CHECK(f.block().held() == "o1/B1");
}

TEST_CASE("mobile robot: drive to the buffer, ask it, drive to the station carrying the part", "[fb][mobile-robot]") {
  fb::BlockTestFixture<fb::MobileRobotBlock> f("robot", "robot-1", fb::Numbers{1, 0, 1}, 0.5);
  const auto spawn = f.send("INIT");
  REQUIRE(names<fb::MobileRobotBlock>(spawn) == Names{"SIM"});
  f.send("SIM_REPLY", reply_to(spawn[0]));
  f.send("PLACE", {{"resource_id", std::string("buffer-1")}, {"dock", fb::Numbers{2, 0, 0}}});
  f.send("PLACE", {{"resource_id", std::string("station-1")}, {"dock", fb::Numbers{0.6, 0, 0}}});
  fb::Data fetch{{"command_id", std::string("f1")}, {"resource_id", std::string("robot-1")},
                 {"operation", std::string("fetch")}, {"order_id", std::string("o1")},
                 {"part", std::string("o1/peg")}, {"part_type", std::string("Peg")},
                 {"source", std::string("buffer-1")}, {"destination", std::string("station-1")}};
  f.send("COMMAND", fetch);
  const auto to_buffer = f.send("START", {{"command_id", std::string("f1")}});
  REQUIRE(names<fb::MobileRobotBlock>(to_buffer) == Names{"SIM"});
  CHECK(fb::get<std::string>(to_buffer[0].data, "kind") == "move");
  CHECK(fb::get<fb::Numbers>(to_buffer[0].data, "path") == fb::Numbers{2, 0, 0, 1, 0, 0, 0});
  CHECK(fb::get<std::string>(to_buffer[0].data, "carried").empty());

  const auto give = f.send("SIM_REPLY", reply_to(to_buffer[0], {{"start_time", 1.0}, {"end_time", 3.0}, {"distance", 1.0}}));
  REQUIRE(names<fb::MobileRobotBlock>(give) == Names{"GIVE"});
  CHECK(fb::get<std::string>(give[0].data, "resource_id") == "buffer-1");
  CHECK(fb::get<std::string>(give[0].data, "part_type") == "Peg");
  CHECK(f.send("GIVE_EVENT", {{"command_id", std::string("other")}, {"state", std::string("succeeded")},
                              {"reason", std::string()}}).empty());
  const auto to_station = f.send("GIVE_EVENT", {{"command_id", fb::get<std::string>(give[0].data, "command_id")},
                                                {"state", std::string("succeeded")}, {"reason", std::string()}});
  REQUIRE(names<fb::MobileRobotBlock>(to_station) == Names{"SIM"});
  CHECK(fb::get<std::string>(to_station[0].data, "carried") == "o1/peg");
  const auto done = f.send("SIM_REPLY", reply_to(to_station[0], {{"start_time", 3.5}, {"end_time", 6.3}, {"distance", 1.4}}));
  REQUIRE(names<fb::MobileRobotBlock>(done) == Names{"DONE"});
  CHECK(fb::get<double>(done[0].data, "distance") == Approx(2.4));
  CHECK(fb::get<double>(done[0].data, "duration") == Approx(4.8));  // moving only, not waiting for the buffer
  CHECK(fb::get<double>(done[0].data, "sim_time") == 6.3);
}

TEST_CASE("mobile robot: a buffer that refuses fails the fetch with its reason", "[fb][mobile-robot]") {
  fb::BlockTestFixture<fb::MobileRobotBlock> f("robot", "robot-1", fb::Numbers{1, 0, 1}, 0.5);
  f.send("SIM_REPLY", reply_to(f.send("INIT")[0]));
  fb::Data fetch{{"command_id", std::string("f1")}, {"resource_id", std::string("robot-1")},
                 {"operation", std::string("fetch")}, {"source", std::string("buffer-9")},
                 {"destination", std::string("station-1")}};
  f.send("COMMAND", fetch);
  const auto unknown = f.send("START", {{"command_id", std::string("f1")}});
  REQUIRE(names<fb::MobileRobotBlock>(unknown) == Names{"FAIL"});
  CHECK(fb::get<std::string>(unknown[0].data, "reason") == "no dock known for buffer-9 or station-1");
  CHECK(f.block().state() == "READY");
}

TEST_CASE("cell-sim world: a move takes distance over speed, and stops at the first collision", "[sim][world]") {
  sim::SimWorld world;
  world.spawn({"table", "", Eigen::Vector3d(1, 0.025, 1), sim::Pose(Eigen::Translation3d(0, -0.025, 0)), true});
  world.spawn({"pad", "", Eigen::Vector3d(0.01, 0.01, 0.01), sim::Pose(Eigen::Translation3d(0, 0.5, 0)), false});
  world.spawn({"box", "", Eigen::Vector3d(0.02, 0.02, 0.02), sim::Pose(Eigen::Translation3d(0, 0.47, 0)), false});

  const sim::MoveResult free = world.move({"pad", {"box"}, {sim::Pose(Eigen::Translation3d(0.3, 0.5, 0.4))}, 0.25, 1});
  CHECK_FALSE(free.collided);
  CHECK(free.distance == Approx(0.5));
  CHECK(free.duration == Approx(2.0));
  CHECK(world.pose("box")->translation().isApprox(Eigen::Vector3d(0.3, 0.47, 0.4)));  // carried along

  // Straight down into the table: the box (carried, 0.03 below the pad) hits it first.
  const sim::MoveResult hit = world.move({"pad", {"box"}, {sim::Pose(Eigen::Translation3d(0.3, 0.0, 0.4))}, 0.25, 1});
  CHECK(hit.collided);
  CHECK(hit.hit_body == "table");
  CHECK(hit.hit_member == "box");
  CHECK(hit.distance == Approx(0.45).margin(0.002));
  CHECK(hit.duration == Approx(hit.distance / 0.25));

  CHECK_THROWS_AS(world.move({"table", {}, {sim::Pose::Identity()}, 1, 1}), sim::SimError);
  CHECK_THROWS_AS(world.spawn({"pad", "", Eigen::Vector3d::Zero(), sim::Pose::Identity(), false}), sim::SimError);
  world.set_static("box", true);
  CHECK(world.is_static("box"));
}

TEST_CASE("device: work queued for an order that has ended fails at once", "[fb][device]") {
  fb::BlockTestFixture<fb::MobileRobotBlock> f("robot", "robot-1", fb::Numbers{1, 0, 1}, 0.5);
  f.send("SIM_REPLY", reply_to(f.send("INIT")[0]));
  f.send("COMMAND", {{"command_id", std::string("f1")}, {"resource_id", std::string("robot-1")},
                     {"operation", std::string("fetch")}, {"order_id", std::string("o1")}});
  f.send("ORDER_ENDED", {{"order_id", std::string("o1")}});
  const auto started = f.send("START", {{"command_id", std::string("f1")}});
  REQUIRE(names<fb::MobileRobotBlock>(started) == Names{"FAIL"});
  CHECK(fb::get<std::string>(started[0].data, "reason") == "order o1 has ended");
}
