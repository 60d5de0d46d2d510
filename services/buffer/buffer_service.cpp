#include "services/buffer/buffer_service.hpp"

#include "capabilitiesPubSubTypes.h"
#include "commandsPubSubTypes.h"
#include "services/blocks/action_block.hpp"
#include "services/blocks/command_lifecycle.hpp"
#include "services/buffer/buffer_block.hpp"
#include "services/dds/service_blocks.hpp"

namespace services {
namespace {

using CommandSubscriber = dds::SubscribeBlock<cell::Command, cell::CommandPubSubType>;
using EventPublisher = dds::PublishBlock<cell::CommandEvent, cell::CommandEventPubSubType>;
using CapabilityWriter = dds::Writer<cell::Capability, cell::CapabilityPubSubType>;

fb::Data command_data(const cell::Command& c) {
  return {{"command_id", c.command_id()}, {"resource_id", c.resource_id()}, {"operation", c.operation()},
          {"part", c.part()}};
}

// A life-cycle output as a command event of the given state.
cell::CommandEvent event_of(const std::string& resource, cell::CommandState state, const fb::Data& d) {
  cell::CommandEvent e;
  e.command_id(fb::get<std::string>(d, "command_id"));
  e.resource_id(resource);
  e.state(state);
  if (const auto it = d.find("reason"); it != d.end()) e.reason(std::get<std::string>(it->second));
  return e;
}

}  // namespace

struct BufferService::Impl {
  dds::ParticipantPtr participant;
  std::unique_ptr<CapabilityWriter> capabilities;
};

BufferService::BufferService(const BufferConfig& config) : resource_(config.id, 256), impl_(std::make_unique<Impl>()) {
  impl_->participant = dds::make_participant(config.id, config.dds);
  dds::QosSettings qos;
  qos.liveliness_lease_s = config.liveliness_lease_s;
  impl_->capabilities = std::make_unique<CapabilityWriter>(impl_->participant, "cell/capabilities", dds::TopicKind::state, qos);

  auto& buffer = resource_.add(std::make_unique<fb::BufferBlock>("buffer", config.id, config.stock));
  resource_.add(std::make_unique<fb::CommandLifecycle>("lifecycle"));
  auto& commands = resource_.add(std::make_unique<CommandSubscriber>("commands", impl_->participant, "cell/commands",
                                                                     dds::TopicKind::events, command_data));
  // One publisher per life-cycle outcome: each maps its event to a CommandEvent state.
  const std::pair<const char*, cell::CommandState> outcomes[] = {
      {"ACCEPTED", cell::ACCEPTED}, {"SUCCEEDED", cell::SUCCEEDED}, {"ABORTED", cell::ABORTED}, {"REJECTED", cell::ABORTED}};
  for (const auto& [output, state] : outcomes) {
    const std::string id = config.id;
    const cell::CommandState s = state;
    const std::string name = std::string("publish_") + output;
    resource_.add(std::make_unique<EventPublisher>(name, impl_->participant, "cell/command_events", dds::TopicKind::events,
                                                   [id, s](const fb::Data& d) { return event_of(id, s, d); }));
    resource_.connect("lifecycle", output, name, "REQ");
  }
  resource_.connect("commands", "IND", "buffer", "COMMAND");
  resource_.connect("buffer", "ACCEPT", "lifecycle", "COMMAND");
  resource_.connect("lifecycle", "START", "buffer", "START");
  resource_.connect("buffer", "DONE", "lifecycle", "DONE");
  resource_.connect("buffer", "FAIL", "lifecycle", "FAIL");

  auto publish_stock = [this, &buffer, config] {
    cell::Capability c;
    c.resource_id(config.id);
    c.kind("buffer");
    c.operations({"give"});
    for (const auto& [type, count] : buffer.stock()) {
      cell::PartStock s;
      s.part_type(type);
      s.count(count);
      c.stock().push_back(s);
    }
    impl_->capabilities->write(c);
  };
  publish_stock();
  resource_.add(std::make_unique<fb::ActionBlock>("capability", [publish_stock](const fb::Data&) { publish_stock(); }));
  resource_.connect("buffer", "STOCK", "capability", "REQ");
  commands.start();
}

BufferService::~BufferService() = default;

}  // namespace services
