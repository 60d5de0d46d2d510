// The cell's device blocks and cell-sim's world, driven with events and no DDS.

#include <catch2/catch.hpp>

#include "services/mobile_robot/mobile_robot_block.hpp"
#include "services/runtime/block_test_fixture.hpp"
#include "services/station/arm_block.hpp"
#include "sim/cell_sim/world_block.hpp"

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
