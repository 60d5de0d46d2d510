// libFuzzer target: random bytes decoded as each sample type the cell reads from the network
// (the first byte chooses the type, the rest is the CDR payload), converted as the services
// convert them, and fed to the blocks that act on them: the arm, the mobile robot and the
// buffer (a command, then its start), the contractor (calls, awards, releases) and cell-sim's
// world (requests). Blocks may refuse and may throw (the runtime catches exceptions); no input
// may crash, hang or leak.
//   fuzz_samples CORPUS_DIR -max_total_time=60

#include <cstdint>
#include <cstring>
#include <exception>

#include <fastdds/rtps/common/SerializedPayload.h>

#include "commandsPubSubTypes.h"
#include "negotiationPubSubTypes.h"
#include "services/blocks/contractor.hpp"
#include "services/buffer/buffer_block.hpp"
#include "services/dds/conversions.hpp"
#include "services/mobile_robot/mobile_robot_block.hpp"
#include "services/runtime/block_test_fixture.hpp"
#include "services/station/arm_block.hpp"
#include "sim/cell_sim/world_block.hpp"
#include "simulationPubSubTypes.h"

namespace {

// Decodes the payload as T; false when CDR refuses it.
template <class T, class PubSubType>
bool decode(const std::uint8_t* data, std::size_t size, T& out) {
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(size));
  if (size > 0) std::memcpy(payload.data, data, size);
  payload.length = static_cast<std::uint32_t>(size);
  PubSubType type;
  return type.deserialize(&payload, &out);
}

// Delivers an event (the resource catches what a block throws, as in a process).
template <class Block>
void deliver(fb::BlockTestFixture<Block>& f, const char* input, const fb::Data& data) {
  f.send(input, data);
}

template <class Block>
void command_then_start(fb::BlockTestFixture<Block>& f, const fb::Data& command) {
  deliver(f, "COMMAND", command);
  deliver(f, "START", {{"command_id", fb::get_or<std::string>(command, "command_id", "")}});
}

void feed_command(const fb::Data& command) {
  fb::BlockTestFixture<fb::ArmBlock> arm("arm", "arm-1", fb::ArmSettings{});
  command_then_start(arm, command);
  fb::BlockTestFixture<fb::MobileRobotBlock> robot("robot", "robot-1", fb::Numbers{1, 0, 1}, 0.5);
  deliver(robot, "INIT", {});
  deliver(robot, "PLACE", {{"resource_id", std::string("buffer-1")}, {"dock", fb::Numbers{2, 0, 0}}});
  command_then_start(robot, command);
  fb::BlockTestFixture<fb::BufferBlock> buffer("buffer", "buffer-1", std::map<std::string, int>{{"Peg", 3}});
  command_then_start(buffer, command);
}

void feed_contractor(const char* input, const fb::Data& data) {
  fb::BlockTestFixture<fb::Contractor> f(
      "contractor", "arm-1", std::set<std::string>{"translate", "give", "fetch", "host"}, true,
      [](const fb::Data& call) { return fb::Contractor::Estimate{true, "", fb::get_or<double>(call, "duration", 0)}; },
      [] { return 10.0; });
  deliver(f, input, data);
  if (std::string(input) != "CFP") return;
  fb::Data award = data;  // the call's own award, to this resource
  award["resource_id"] = std::string("arm-1");
  deliver(f, "AWARD", award);
}

}  // namespace

// Decoding is not wrapped: an exception out of a type support's deserialize would leave
// Fast DDS's reader thread in a process of the cell, so here it is a crash too.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t kind = data[0] % 5;
  ++data;
  --size;
  if (kind == 0) {
    cell::Command c;
    if (decode<cell::Command, cell::CommandPubSubType>(data, size, c)) feed_command(dds::to_data(c));
  } else if (kind == 1) {
    cell::SimRequest r;
    if (decode<cell::SimRequest, cell::SimRequestPubSubType>(data, size, r)) {
      fb::BlockTestFixture<sim::WorldBlock> world("world", 1000.0);
      deliver(world, "REQUEST", dds::to_data(r));
      deliver(world, "TICK", {});
    }
  } else if (kind == 2) {
    cell::CallForProposals c;
    if (decode<cell::CallForProposals, cell::CallForProposalsPubSubType>(data, size, c)) feed_contractor("CFP", dds::to_data(c));
  } else if (kind == 3) {
    cell::Award a;
    if (decode<cell::Award, cell::AwardPubSubType>(data, size, a)) feed_contractor("AWARD", dds::to_data(a));
  } else {
    cell::Release r;
    if (decode<cell::Release, cell::ReleasePubSubType>(data, size, r)) feed_contractor("RELEASE", dds::to_data(r));
  }
  return 0;
}
