// The cell's device blocks and cell-sim's world, driven with events and no DDS.

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <thread>

#include <set>

#include <catch2/catch.hpp>

#include "services/buffer/buffer_block.hpp"
#include "services/mobile_robot/mobile_robot_block.hpp"
#include "services/runtime/block_test_fixture.hpp"
#include "services/state/cell_store.hpp"
#include "services/station/arm_block.hpp"
#include "sim/cell_sim/world_block.hpp"
#include "sim/world/motion_time.hpp"
#include "sim/world/sim_world.hpp"

namespace {

using Names = std::vector<std::string>;
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

TEST_CASE("arm: a grip places palm, fingers and carriage, a second grip replaces them", "[fb][arm]") {
  fb::BlockTestFixture<fb::ArmBlock> f("arm", "arm-1", fb::ArmSettings{});
  const fb::Data grasp{{"part", std::string("o1/B1")}, {"path", fb::Numbers{0, 0.1, 0, 1, 0, 0, 0}}, {"opening", 0.02}};
  for (int round = 0; round < 2; ++round) {
    const std::string id = "g" + std::to_string(round);
    CHECK(fb::event_names(f.send("COMMAND", command(id, "grip", grasp))) == Names{"ACCEPT"});
    const auto requests = f.send("START", {{"command_id", id}});
    REQUIRE(requests.size() == (round == 0 ? 4u : 8u));
    // The fingers stand 20 mm apart, on either side of the gripper's origin.
    const auto& finger = requests[round == 0 ? 1 : 5].data;
    CHECK(fb::get<std::string>(finger, "body_id") == "arm-1/finger-1");
    CHECK(fb::get<fb::Numbers>(finger, "placement")[0] == Approx(-0.01 - fb::GripperGeometry{}.finger_thickness / 2));
    for (std::size_t i = 0; i + 1 < requests.size(); ++i) CHECK(f.send("SIM_REPLY", reply_to(requests[i])).empty());
    CHECK(fb::event_names(f.send("SIM_REPLY", reply_to(requests.back()))) == Names{"DONE"});
  }
  CHECK(f.block().held() == "o1/B1");
}

TEST_CASE("arm: a grip naming carried bodies moves them with the gripped part until the release", "[fb][arm][state]") {
  fb::BlockTestFixture<fb::ArmBlock> f("arm", "arm-1", fb::ArmSettings{});
  const auto dir = std::filesystem::temp_directory_path() / ("agile-cell-blocks-" + std::to_string(::getpid())) / "carried";
  std::filesystem::remove_all(dir);
  state::CellStore store(dir);
  store.open_buffer("buffer-1", {{"Base", 1}, {"Member", 2}});
  for (const auto& [type, part] : {std::pair{"Base", "o1/base"}, {"Member", "o1/m1"}, {"Member", "o1/m2"}}) {
    store.give("buffer-1", type, "o1", part, "robot-1");
    store.deliver("o1", part, "station-1");
  }
  REQUIRE(f.block().keep_state_in(store).empty());
  const auto places = [&] {
    std::set<std::string> out;
    for (const auto& p : store.parts("o1")) out.insert(std::string(state::place_name(p.place)) + ":" + p.holder);
    return out;
  };
  const fb::Data grasp{{"part", std::string("o1/base")}, {"carried", fb::join_names({"o1/m1", "o1/m2"})},
                       {"order_id", std::string("o1")}, {"path", fb::Numbers{0, 0.1, 0, 1, 0, 0, 0}}, {"opening", 0.02}};
  REQUIRE(fb::event_names(f.send("COMMAND", command("g", "grip", grasp))) == Names{"ACCEPT"});
  const auto spawns = f.send("START", {{"command_id", std::string("g")}});
  for (const auto& request : spawns) f.send("SIM_REPLY", reply_to(request));
  CHECK(f.block().carried() == std::vector<std::string>{"o1/m1", "o1/m2"});
  const auto move_of = [&](const std::string& id) {
    REQUIRE(fb::event_names(f.send("COMMAND", command(id, "translate", {{"path", fb::Numbers{0, 0.2, 0, 1, 0, 0, 0}}}))) ==
            Names{"ACCEPT"});
    const auto out = f.send("START", {{"command_id", id}});
    REQUIRE(out.size() == 1);
    const auto carried = fb::split_names(fb::get<std::string>(out[0].data, "carried"));
    f.send("SIM_REPLY", reply_to(out[0]));
    return carried;
  };
  const auto holding = move_of("t1");
  for (const char* body : {"o1/base", "o1/m1", "o1/m2"}) CHECK(std::count(holding.begin(), holding.end(), body) == 1);
  CHECK(places() == std::set<std::string>{"in_gripper:arm-1"});
  // The release says what the parts go into: the state records them placed with it, in one
  // transaction (a twin that dies right after cannot leave them "at the dock").
  REQUIRE(fb::event_names(f.send("COMMAND", command("r", "release", {{"order_id", std::string("o1")},
                                                                         {"destination", std::string("product")}}))) ==
          Names{"ACCEPT"});
  f.send("START", {{"command_id", std::string("r")}});
  CHECK(f.block().carried().empty());
  CHECK(places() == std::set<std::string>{"placed:"});
  const auto after = move_of("t2");
  CHECK(std::count(after.begin(), after.end(), "o1/m1") == 0);
  CHECK(std::count(after.begin(), after.end(), "o1/base") == 0);
}

TEST_CASE("mobile robot: drive to the buffer, ask it, drive to the station carrying the part", "[fb][mobile-robot]") {
  fb::BlockTestFixture<fb::MobileRobotBlock> f("robot", "robot-1", fb::Numbers{1, 0, 1}, 0.5);
  const auto spawn = f.send("INIT");
  REQUIRE(fb::event_names(spawn) == Names{"SIM"});
  f.send("SIM_REPLY", reply_to(spawn[0]));
  f.send("PLACE", {{"resource_id", std::string("buffer-1")}, {"dock", fb::Numbers{2, 0, 0}}});
  f.send("PLACE", {{"resource_id", std::string("station-1")}, {"dock", fb::Numbers{0.6, 0, 0}}});
  fb::Data fetch{{"command_id", std::string("f1")}, {"resource_id", std::string("robot-1")},
                 {"operation", std::string("fetch")}, {"order_id", std::string("o1")},
                 {"part", std::string("o1/peg")}, {"part_type", std::string("Peg")},
                 {"source", std::string("buffer-1")}, {"destination", std::string("station-1")},
                 {"source_award", std::string("o1/give/Peg")}};
  REQUIRE(fb::event_names(f.send("COMMAND", fetch)) == Names{"ACCEPT"});
  const auto to_buffer = f.send("START", {{"command_id", std::string("f1")}});
  REQUIRE(fb::event_names(to_buffer) == Names{"SIM"});
  CHECK(fb::get<std::string>(to_buffer[0].data, "kind") == "move");
  CHECK(fb::get<fb::Numbers>(to_buffer[0].data, "path") == fb::Numbers{2, 0, 0, 1, 0, 0, 0});
  CHECK(fb::get<std::string>(to_buffer[0].data, "carried").empty());

  const auto give = f.send("SIM_REPLY", reply_to(to_buffer[0], {{"start_time", 1.0}, {"end_time", 3.0}, {"distance", 1.0}}));
  REQUIRE(fb::event_names(give) == Names{"GIVE"});
  CHECK(fb::get<std::string>(give[0].data, "resource_id") == "buffer-1");
  CHECK(fb::get<std::string>(give[0].data, "part_type") == "Peg");
  CHECK(fb::get<std::string>(give[0].data, "award") == "o1/give/Peg");  // the buffer's award, for the buffer
  CHECK(f.send("GIVE_EVENT", {{"command_id", std::string("other")}, {"state", std::string("succeeded")},
                              {"reason", std::string()}}).empty());
  const auto to_station = f.send("GIVE_EVENT", {{"command_id", fb::get<std::string>(give[0].data, "command_id")},
                                                {"state", std::string("succeeded")}, {"reason", std::string()}});
  REQUIRE(fb::event_names(to_station) == Names{"SIM"});
  CHECK(fb::get<std::string>(to_station[0].data, "carried") == "o1/peg");
  const auto done = f.send("SIM_REPLY", reply_to(to_station[0], {{"start_time", 3.5}, {"end_time", 6.3}, {"distance", 1.4}}));
  REQUIRE(fb::event_names(done) == Names{"DONE"});
  CHECK(fb::get<double>(done[0].data, "distance") == Approx(2.4));
  CHECK(fb::get<double>(done[0].data, "duration") == Approx(4.8));  // moving only, not waiting for the buffer
  CHECK(fb::get<double>(done[0].data, "sim_time") == 6.3);
}

TEST_CASE("mobile robot: a buffer that refuses fails the fetch with its reason", "[fb][mobile-robot]") {
  fb::BlockTestFixture<fb::MobileRobotBlock> f("robot", "robot-1", fb::Numbers{1, 0, 1}, 0.5);
  f.send("SIM_REPLY", reply_to(f.send("INIT")[0]));
  fb::Data fetch{{"command_id", std::string("f1")}, {"resource_id", std::string("robot-1")},
                 {"operation", std::string("fetch")}, {"source", std::string("buffer-9")},
                 {"destination", std::string("station-1")}, {"part_type", std::string("Peg")},
                 {"source_award", std::string("o1/give/Peg")}};
  REQUIRE(fb::event_names(f.send("COMMAND", fetch)) == Names{"ACCEPT"});
  const auto unknown = f.send("START", {{"command_id", std::string("f1")}});
  REQUIRE(fb::event_names(unknown) == Names{"FAIL"});
  CHECK(fb::get<std::string>(unknown[0].data, "reason") == "no dock known for buffer-9 or station-1");
  CHECK(f.block().state() == "READY");
}

TEST_CASE("mobile robot: a give goes again, the same command, until its final answer is heard",
          "[fb][mobile-robot]") {
  // Sent again at the first look after 0 ms: no test waits on the clock.
  fb::BlockTestFixture<fb::MobileRobotBlock> f("robot", "robot-1", fb::Numbers{1, 0, 1}, 0.5, std::chrono::milliseconds(0));
  f.send("SIM_REPLY", reply_to(f.send("INIT")[0]));
  f.send("PLACE", {{"resource_id", std::string("buffer-1")}, {"dock", fb::Numbers{2, 0, 0}}});
  f.send("PLACE", {{"resource_id", std::string("station-1")}, {"dock", fb::Numbers{0.6, 0, 0}}});
  CHECK(f.send("TICK").empty());  // nothing to look after yet
  fb::Data fetch{{"command_id", std::string("f1")}, {"resource_id", std::string("robot-1")},
                 {"operation", std::string("fetch")}, {"order_id", std::string("o1")},
                 {"part", std::string("o1/peg")}, {"part_type", std::string("Peg")},
                 {"source", std::string("buffer-1")}, {"destination", std::string("station-1")},
                 {"source_award", std::string("o1/give/Peg")}};
  f.send("COMMAND", fetch);
  const auto to_buffer = f.send("START", {{"command_id", std::string("f1")}});
  const auto give = f.send("SIM_REPLY", reply_to(to_buffer[0], {{"start_time", 1.0}, {"end_time", 3.0}, {"distance", 1.0}}));
  REQUIRE(fb::event_names(give) == Names{"GIVE"});
  const auto again = f.send("TICK");
  REQUIRE(fb::event_names(again) == Names{"GIVE"});
  CHECK(again[0].data == give[0].data);  // the same command id: the buffer carries it out once
  // An answer to another robot's give is not an answer to this one.
  f.send("GIVE_EVENT", {{"command_id", std::string("f9/give")}, {"state", std::string("accepted")}, {"reason", std::string()}});
  CHECK(fb::event_names(f.send("TICK")) == Names{"GIVE"});
  const std::string& id = fb::get<std::string>(give[0].data, "command_id");
  // Accepted is not the end: a buffer that ends now takes the answer with it.
  f.send("GIVE_EVENT", {{"command_id", id}, {"state", std::string("accepted")}, {"reason", std::string()}});
  CHECK(fb::event_names(f.send("TICK")) == Names{"GIVE"});
  CHECK(f.block().state() == "WAIT_GIVE");
  const auto to_station =
      f.send("GIVE_EVENT", {{"command_id", id}, {"state", std::string("succeeded")}, {"reason", std::string()}});
  REQUIRE(fb::event_names(to_station) == Names{"SIM"});
  CHECK(f.send("TICK").empty());
}

TEST_CASE("buffer: a give whose answer died with the process is undone, or answered again, never done twice",
          "[fb][buffer][state]") {
  const auto dir = std::filesystem::temp_directory_path() / ("agile-cell-blocks-" + std::to_string(::getpid())) / "give";
  std::filesystem::remove_all(dir);
  state::CellStore store(dir);
  const std::map<std::string, int> seed{{"Peg", 2}};
  const fb::Data give{{"command_id", std::string("o1/g1")}, {"resource_id", std::string("buffer-1")},
                      {"operation", std::string("give")}, {"order_id", std::string("o1")},
                      {"part", std::string("o1/peg")}, {"part_type", std::string("Peg")},
                      {"destination", std::string("robot-1")}};
  {
    // The process before: it takes the give on (the node records that) and counts the part
    // out, and is killed before it answers.
    fb::BlockTestFixture<fb::BufferBlock> before("buffer", "buffer-1", seed);
    CHECK(before.block().keep_state_in(store).empty());
    REQUIRE(fb::event_names(before.send("COMMAND", give)) == Names{"ACCEPT"});
    store.command_taken({"buffer-1", "o1/g1", "o1", "give", "o1/peg"});
    REQUIRE(fb::event_names(before.send("START", {{"command_id", std::string("o1/g1")}})) ==
            Names{"DONE", "CAPABILITY"});
    CHECK(before.block().count("Peg") == 1);
  }
  fb::BlockTestFixture<fb::BufferBlock> after("buffer", "buffer-1", seed);
  SECTION("killed before the answer: the part is back, and the give is the new process's to abort") {
    const std::string recovered = after.block().keep_state_in(store);
    CHECK_THAT(recovered, Catch::Contains("o1/peg (Peg) back in stock"));
    CHECK(after.block().count("Peg") == 2);
    CHECK(store.inventory().at("Peg").in_transit == 0);
    CHECK(store.take_interrupted("buffer-1").size() == 1);
  }
  SECTION("killed after it ended the command, before the answer went out: a repeat is answered, not done") {
    store.command_ended("buffer-1", "o1/g1");
    CHECK_THAT(after.block().keep_state_in(store), !Catch::Contains("back in stock"));
    CHECK(after.block().count("Peg") == 1);
    REQUIRE(fb::event_names(after.send("COMMAND", give)) == Names{"ACCEPT"});
    REQUIRE(fb::event_names(after.send("START", {{"command_id", std::string("o1/g1")}})) == Names{"DONE"});
    CHECK(after.block().count("Peg") == 1);
    CHECK(store.inventory().at("Peg").in_transit == 1);
    CHECK(store.inventory().at("Peg").in_buffers == 1);
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("cell-sim world: a move takes distance over speed, and stops at the first collision", "[sim][world]") {
  sim::SimWorld world;
  world.spawn({"table", "", Eigen::Vector3d(1, 0.025, 1), sim::Pose(Eigen::Translation3d(0, -0.025, 0)), true, "", false});
  world.spawn({"pad", "", Eigen::Vector3d(0.01, 0.01, 0.01), sim::Pose(Eigen::Translation3d(0, 0.5, 0)), false, "", false});
  world.spawn({"box", "", Eigen::Vector3d(0.02, 0.02, 0.02), sim::Pose(Eigen::Translation3d(0, 0.47, 0)), false, "", false});

  const sim::MoveResult free = world.move({"pad", {"box"}, {sim::Pose(Eigen::Translation3d(0.3, 0.5, 0.4))}, 0.25, 1, "", ""});
  CHECK_FALSE(free.collided);
  CHECK(free.distance == Approx(0.5));
  CHECK(free.duration == Approx(2.0));
  CHECK(world.pose("box")->translation().isApprox(Eigen::Vector3d(0.3, 0.47, 0.4)));  // carried along

  // A turn slower than the translation takes as long as the turn: the rule a twin's quote
  // times the arm's paths by (sim::segment_duration).
  sim::Pose turned(Eigen::AngleAxisd(1.5, Eigen::Vector3d::UnitY()));
  turned.translation() = Eigen::Vector3d(0.3, 0.55, 0.4);  // 0.05 m: 0.2 s
  const sim::Pose before = *world.pose("pad");
  const sim::MoveResult turn = world.move({"pad", {"box"}, {turned}, 0.25, 1, "", ""});
  CHECK(turn.duration == Approx(1.5));
  CHECK(turn.duration == Approx(sim::segment_duration(before, turned, 0.25, 1)));

  // Straight down into the table: the box (carried, 0.03 below the pad) hits it first.
  turned.translation().y() = 0.0;
  const sim::MoveResult hit = world.move({"pad", {"box"}, {turned}, 0.25, 1, "", ""});
  CHECK(hit.collided);
  CHECK(hit.hit_body == "table");
  CHECK(hit.hit_member == "box");
  CHECK(hit.distance == Approx(0.5).margin(0.002));
  CHECK(hit.duration == Approx(hit.distance / 0.25));

  CHECK_THROWS_AS(world.move({"table", {}, {sim::Pose::Identity()}, 1, 1, "", ""}), sim::SimError);
  CHECK_THROWS_AS(world.spawn({"pad", "", Eigen::Vector3d::Zero(), sim::Pose::Identity(), false, "", false}), sim::SimError);
  world.set_static("box", true);
  CHECK(world.is_static("box"));
}

TEST_CASE("cell-sim world: a body turned into a thread may go into its mate, what moves with it may not", "[sim][world]") {
  sim::SimWorld world;
  // A bolt's stand-in (static), a nut that overlaps it 0.5 mm all along, a pad that carries it.
  world.spawn({"bolt", "", Eigen::Vector3d(0.006, 0.02, 0.006), sim::Pose(Eigen::Translation3d(0, 0.02, 0)), true, "", false});
  world.spawn({"nut", "", Eigen::Vector3d(0.012, 0.004, 0.012), sim::Pose(Eigen::Translation3d(0, 0.030, 0)), false, "", false});
  world.spawn({"pad", "", Eigen::Vector3d(0.004, 0.004, 0.004), sim::Pose(Eigen::Translation3d(0.02, 0.040, 0)), false, "", false});
  const sim::Pose turned_down(Eigen::Translation3d(0.02, 0.035, 0) * Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY()));
  const sim::MoveResult plain = world.move({"pad", {"nut"}, {turned_down}, 0.25, 1, "", ""});
  CHECK(plain.collided);  // the nut is in the bolt from the start
  CHECK(plain.hit_member == "nut");
  const sim::MoveResult screwed = world.move({"pad", {"nut"}, {turned_down}, 0.25, 1, "nut", "bolt"});
  CHECK_FALSE(screwed.collided);
  CHECK(screwed.duration == Approx(0.5));  // half a radian at 1 rad/s
  // The pad, which does not turn into the thread, hits the bolt: its check keeps the bolt.
  const sim::Pose pad_into_bolt(Eigen::Translation3d(0.0, 0.035, 0));
  const sim::MoveResult pad = world.move({"pad", {"nut"}, {pad_into_bolt}, 0.25, 1, "nut", "bolt"});
  CHECK(pad.collided);
  CHECK(pad.hit_member == "pad");
  CHECK_THROWS_AS(world.move({"pad", {}, {turned_down}, 0.25, 1, "nut", "bolt"}), sim::SimError);  // not carried
  CHECK_THROWS_AS(world.move({"pad", {"nut"}, {turned_down}, 0.25, 1, "nut", "pad"}), sim::SimError);  // no obstacle
}

TEST_CASE("device: work queued for an order that has ended fails at once", "[fb][device]") {
  fb::BlockTestFixture<fb::MobileRobotBlock> f("robot", "robot-1", fb::Numbers{1, 0, 1}, 0.5);
  f.send("SIM_REPLY", reply_to(f.send("INIT")[0]));
  f.send("COMMAND", {{"command_id", std::string("f1")}, {"resource_id", std::string("robot-1")},
                     {"operation", std::string("fetch")}, {"order_id", std::string("o1")},
                     {"source", std::string("buffer-1")}, {"destination", std::string("station-1")},
                     {"part_type", std::string("Peg")}, {"source_award", std::string("o1/give/Peg")}});
  f.send("ORDER_ENDED", {{"order_id", std::string("o1")}});
  const auto started = f.send("START", {{"command_id", std::string("f1")}});
  REQUIRE(fb::event_names(started) == Names{"FAIL"});
  CHECK(fb::get<std::string>(started[0].data, "reason") == "order o1 has ended");
}

namespace {

const fb::Data kGrasp{{"part", std::string("o1/B1")}, {"order_id", std::string("o1")},
                      {"path", fb::Numbers{0, 0.1, 0, 1, 0, 0, 0}}, {"opening", 0.02}};

// The reason an arm refuses the command, "" if it accepts it.
std::string arm_refusal(fb::BlockTestFixture<fb::ArmBlock>& f, const std::string& operation, fb::Data fields) {
  static int count = 0;
  const auto out = f.send("COMMAND", command("c" + std::to_string(++count), operation, std::move(fields)));
  REQUIRE(out.size() == 1);
  if (out[0].name == "ACCEPT") return "";
  REQUIRE(out[0].name == "REFUSE");
  return fb::get<std::string>(out[0].data, "reason");
}

fb::Data with(fb::Data d, const std::string& key, fb::Value value) {
  d[key] = std::move(value);
  return d;
}

}  // namespace

TEST_CASE("device: a malformed command is refused with the field, never started", "[fb][device][hostile]") {
  fb::BlockTestFixture<fb::ArmBlock> f("arm", "arm-1", fb::ArmSettings{});
  fb::CellBounds bounds;
  bounds.min = {-5, -1, -5};
  bounds.max = {5, 3, 5};
  f.block().set_bounds(bounds);
  const double nan = std::nan(""), inf = HUGE_VAL;
  const fb::Data move{{"part", std::string("o1/B1")}, {"path", fb::Numbers{0.1, 0.2, 0.3, 1, 0, 0, 0}}};
  CHECK(arm_refusal(f, "grip", kGrasp).empty());
  CHECK(arm_refusal(f, "translate", move).empty());
  CHECK(arm_refusal(f, "translate", with(move, "path", fb::Numbers{nan, 0.2, 0.3, 1, 0, 0, 0})) ==
        "path[0]: position (nan, 0.2, 0.3) is not finite");
  CHECK(arm_refusal(f, "translate", with(move, "path", fb::Numbers{inf, 0.2, 0.3, 1, 0, 0, 0})) ==
        "path[0]: position (inf, 0.2, 0.3) is not finite");
  CHECK(arm_refusal(f, "translate", with(move, "path", fb::Numbers{0, 0, 0, 1, 0, 0, 0, 0.1, 0.2, 0.3, nan, 0, 0, 0}))
            .find("path[1]: orientation is not finite") == 0);
  CHECK(arm_refusal(f, "translate", with(move, "path", fb::Numbers{0.1, 0.2, 0.3, 0.5, 0, 0, 0})) ==
        "path[0]: orientation is not a unit quaternion (length 0.500000)");
  CHECK(arm_refusal(f, "translate", with(move, "path", fb::Numbers{9, 0.2, 0.3, 1, 0, 0, 0})) ==
        "path[0]: position (9, 0.2, 0.3) is outside the cell (-5, -1, -5) to (5, 3, 5)");
  CHECK(arm_refusal(f, "translate", with(move, "path", fb::Numbers{})) == "path: 0 poses, not 1 to 2048");
  fb::Numbers long_path;
  for (int i = 0; i < 2049; ++i) long_path.insert(long_path.end(), {0, 0, 0, 1, 0, 0, 0});
  CHECK(arm_refusal(f, "translate", with(move, "path", long_path)) == "path: 2049 poses, not 0 to 2048");
  CHECK(arm_refusal(f, "grip", with(kGrasp, "opening", -0.01)) == "opening: -0.01 is below 0");
  CHECK(arm_refusal(f, "grip", with(kGrasp, "opening", nan)) == "opening: nan is not finite");
  CHECK(arm_refusal(f, "grip", with(kGrasp, "opening", 0.5)) == "opening: 0.5 m is wider than the gripper opens (0.2 m)");
  CHECK(arm_refusal(f, "grip", with(kGrasp, "part", std::string(300, 'x'))) == "part: 300 characters, more than 255");
  CHECK(arm_refusal(f, "grip", with(kGrasp, "carried", std::string("o1/B2"))).empty());  // a subassembly's member
  std::vector<std::string> many;
  for (int i = 0; i < 61; ++i) many.push_back("o1/M" + std::to_string(i));
  CHECK(arm_refusal(f, "grip", with(kGrasp, "carried", fb::join_names(many))) == "carried: 61 names, more than 60");
  CHECK(arm_refusal(f, "grip", with(kGrasp, "carried", fb::join_names({"o1/B2", "o1/B2"}))) ==
        "carried: names a body twice, or the gripped part");
  CHECK(arm_refusal(f, "grip", with(kGrasp, "carried", std::string("o1/B1"))) ==
        "carried: names a body twice, or the gripped part");
  CHECK(arm_refusal(f, "grip", with(kGrasp, "carried", std::string("arm-1/palm"))) == "carried: arm-1/palm is the arm's own");
  CHECK(arm_refusal(f, "grip", with(with(kGrasp, "part", std::string()), "carried", std::string("o1/B2"))) ==
        "carried: bodies carried with no part gripped");
  CHECK(arm_refusal(f, "grip", with(kGrasp, "sim_time", nan)) == "sim_time: nan is not finite");
  // A screw: its turns, pitch and the body it turns into, and a path that turns as far.
  fb::Numbers helix;
  for (int k = 0; k <= 36; ++k) {
    const Eigen::Quaterniond q(Eigen::AngleAxisd(k * M_PI / 18, Eigen::Vector3d::UnitY()));
    helix.insert(helix.end(), {0.1, 0.2 - 0.002 * k / 36, 0.3, q.w(), q.x(), q.y(), q.z()});
  }
  fb::Data screw = move;
  screw["path"] = helix;
  screw["turns"] = 1.0;
  screw["pitch"] = 0.002;
  screw["destination"] = std::string("o1/bolt");
  CHECK(arm_refusal(f, "screw", screw).empty());
  CHECK(arm_refusal(f, "screw", with(screw, "turns", 3.0)) == "path: turns 1 times, not the 3 the command says");
  CHECK(arm_refusal(f, "screw", with(screw, "turns", 0.0)) == "turns: must be above 0 and at most 1000");
  CHECK(arm_refusal(f, "screw", with(screw, "pitch", nan)) == "pitch: nan is not finite");
  CHECK(arm_refusal(f, "screw", with(screw, "destination", std::string())) == "destination: empty");
  CHECK(f.block().refused() == 21);
  CHECK(f.block().last_refusal().find("destination: empty") != std::string::npos);
  // A refused command was never taken: starting it finds nothing.
  CHECK(fb::get<std::string>(f.send("START", {{"command_id", std::string("c3")}})[0].data, "reason") == "unknown command");
}

TEST_CASE("device: only the order its contractor authorises commands it", "[fb][device][hostile]") {
  fb::BlockTestFixture<fb::ArmBlock> f("arm", "arm-1", fb::ArmSettings{});
  f.block().authorize_with([](const fb::Data& c) {
    return fb::get_or<std::string>(c, "order_id", "") == "ok1" ? "" : "arm-1 is reserved by ok1";
  });
  CHECK(arm_refusal(f, "grip", with(kGrasp, "order_id", std::string("ok1"))).empty());
  const auto out = f.send("COMMAND", command("x1", "release", {{"order_id", std::string("intruder")}}));
  REQUIRE(fb::event_names(out) == Names{"REFUSE"});
  CHECK(fb::get<std::string>(out[0].data, "reason") == "arm-1 is reserved by ok1");
  CHECK(fb::get<std::string>(out[0].data, "order_id") == "intruder");
}

TEST_CASE("cell-sim: requests are checked, and an order's bodies are its own", "[sim][world][hostile]") {
  fb::CellBounds bounds;
  bounds.min = {-5, -1, -5};
  bounds.max = {5, 3, 5};
  // A request for an order that has not hired its requester waits 50 ms for the hire here.
  fb::BlockTestFixture<sim::WorldBlock> f("world", 1000.0, bounds, 0.05, std::chrono::milliseconds(50));
  int count = 0;
  const auto ask = [&](const std::string& requester, const std::string& kind, const std::string& body, fb::Data d) {
    d["request_id"] = "r" + std::to_string(++count);
    d["requester"] = requester;
    d["kind"] = kind;
    d["body_id"] = body;
    std::vector<fb::Event> out = f.send("REQUEST", d);
    for (int i = 0; i < 100; ++i, out = f.send("TICK")) {  // moves are answered when the sim clock gets there
      for (const fb::Event& e : out) {
        if (e.name == "REPLY" && fb::get<std::string>(e.data, "request_id") == "r" + std::to_string(count)) {
          return fb::get<bool>(e.data, "ok") ? std::string() : fb::get<std::string>(e.data, "error");
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return std::string("no reply");
  };
  const fb::Data box{{"placement", fb::Numbers{0, 0.5, 0, 1, 0, 0, 0}}, {"half_extents", fb::Numbers{0.01, 0.01, 0.01}}};
  const fb::Data table{{"placement", fb::Numbers{0, -0.025, 0, 1, 0, 0, 0}}, {"half_extents", fb::Numbers{1, 0.025, 1}},
                      {"fixture", true}, {"is_static", true}};
  CHECK(ask("station-1", "spawn", "table", table).empty());
  CHECK(ask("ok1", "spawn", "ok1/B1", box).empty());
  CHECK(ask("arm-1", "spawn", "arm-1/palm", box).empty());
  CHECK(ask("ok1", "spawn", "ok1/B2", with(box, "half_extents", fb::Numbers{-1, 0.01, 0.01})) ==
        "half_extents: (-1, 0.01, 0.01) has a negative size");
  CHECK(ask("ok1", "spawn", "ok1/B2", with(box, "placement", fb::Numbers{0, 0.5, 0, 0, 0, 0, 0})) ==
        "placement[0]: orientation is not a unit quaternion (length 0.000000)");
  CHECK(ask("ok1", "spawn", "ok1/B2", with(box, "mesh_uri", std::string("/nonexistent.obj"))) ==
        "mesh_uri: /nonexistent.obj is not a readable file");
  CHECK(ask("intruder", "spawn", "x", with(box, "scene", std::string("ok1"))) == "scene ok1 is not intruder's");
  CHECK(ask("ok1", "spawn", "ok1/B2", with(box, "mesh_scale", -1.0)) ==
        "mesh_scale: -1.000000 metres per unit is not a length unit (1e-6 to 1000)");
  CHECK(ask("ok1", "spawn", "ok1/B2", with(box, "mesh_scale", std::nan(""))) == "mesh_scale: nan is not finite");
  CHECK(ask("ok1", "spawn", "ok1/mm", with(with(box, "mesh_uri", std::string(TEST_DATA_DIR "/planning/units/meshes/block_mm.stl")),
                                           "mesh_scale", 1e-3)).empty());

  const fb::Data move{{"path", fb::Numbers{0.1, 0.5, 0, 1, 0, 0, 0}}, {"speed", 1.0}, {"angular_speed", 1.0}};
  CHECK(ask("ok1", "move", "ok1/B1", with(move, "speed", std::nan(""))) == "speed: nan is not finite");
  CHECK(ask("ok1", "move", "ok1/B1", with(move, "speed", 0.0)) == "speed: must be above 0");
  CHECK(ask("ok1", "move", "ok1/B1", with(move, "path", fb::Numbers{0, 1e9, 0, 1, 0, 0, 0})).find("outside the cell") !=
        std::string::npos);
  // Another requester may not touch ok1's part, nor anyone the cell's fixtures.
  CHECK(ask("intruder", "remove", "ok1/B1", {}) == "ok1/B1 belongs to ok1, not to intruder");
  CHECK(ask("intruder", "set_movable", "table", {}) == "table is a fixture of the cell");
  CHECK(ask("station-1", "remove", "table", {}) == "table is a fixture of the cell");
  CHECK(ask("intruder", "move", "ok1/B1", move) == "ok1/B1 belongs to ok1, not to intruder");
  // The arm carries ok1's part only while ok1 has hired it.
  const fb::Data carry = with(with(move, "carried", std::string("ok1/B1")), "order_id", std::string("ok1"));
  CHECK(ask("arm-1", "move", "arm-1/palm", carry) == "ok1/B1 belongs to order ok1, which has not hired arm-1");
  f.send("HIRED", {{"resource_id", std::string("arm-1")}, {"order_id", std::string("ok1")}});
  CHECK(ask("arm-1", "move", "arm-1/palm", carry).empty());
  CHECK(f.block().world().pose("ok1/B1")->translation().x() == Approx(0.1));
  // A request that overtook its hire (another topic) is carried out when the hire comes.
  CHECK(ask("arm-2", "spawn", "arm-2/palm", box).empty());
  fb::Data early = with(carry, "request_id", std::string("early"));
  early["requester"] = std::string("arm-2");
  early["kind"] = std::string("move");
  early["body_id"] = std::string("arm-2/palm");
  const auto answered = [](const std::vector<fb::Event>& out) {
    return std::any_of(out.begin(), out.end(), [](const fb::Event& e) {
      return e.name == "REPLY" && fb::get<std::string>(e.data, "request_id") == "early";
    });
  };
  CHECK_FALSE(answered(f.send("REQUEST", early)));
  std::vector<fb::Event> out = f.send("HIRED", {{"resource_id", std::string("arm-2")}, {"order_id", std::string("ok1")}});
  for (int i = 0; i < 1000 && !answered(out); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    out = f.send("TICK");
  }
  REQUIRE(answered(out));
  for (const fb::Event& e : out) {
    if (e.name == "REPLY") CHECK(fb::get<bool>(e.data, "ok"));
  }
  // A requester with no bodies of its own is no resource of the cell: refused at once.
  fb::Data stranger = with(move, "order_id", std::string("ok1"));
  stranger["request_id"] = std::string("stranger");
  stranger["requester"] = std::string("intruder");
  stranger["kind"] = std::string("move");
  stranger["body_id"] = std::string("ok1/B1");
  out = f.send("REQUEST", stranger);
  CHECK(std::any_of(out.begin(), out.end(), [](const fb::Event& e) {
    return e.name == "REPLY" && fb::get_or<std::string>(e.data, "error", "") == "ok1/B1 belongs to order ok1, which has not hired intruder";
  }));
  // A screw lets its part into one body of its own order only: not through the table.
  const fb::Data screw = with(with(carry, "turning", std::string("ok1/B1")), "into", std::string("table"));
  CHECK(ask("arm-1", "move", "arm-1/palm", screw) == "into: table is a fixture of the cell");
  CHECK(ask("arm-1", "move", "arm-1/palm", with(screw, "into", std::string())) == "turning, into: one without the other");
  CHECK(ask("intruder", "move", "arm-1/palm", carry) == "arm-1/palm belongs to arm-1, not to intruder");
  f.send("ORDER_ENDED", {{"order_id", std::string("ok1")}});
  CHECK_FALSE(f.block().world().pose("ok1/B1"));
  CHECK(f.block().world().pose("table"));
}
