#include "services/buffer/buffer_service.hpp"

#include "services/buffer/buffer_block.hpp"

namespace services {

BufferService::BufferService(BufferConfig config) : resource_(config.node.id, 256) {
  config.node.kind = "buffer";
  config.node.exclusive = false;
  config.node.offers = {"give"};
  // Robots ask at the same time: gives wait their turn (each is done at once).
  config.node.when_busy = fb::CommandLifecycle::WhenBusy::queue;
  config.node.commanded_by_destination = true;  // the robot that takes the part
  config.node.dock = config.node.position;
  auto& buffer = resource_.add(std::make_unique<fb::BufferBlock>("buffer", config.node.id, config.stock));
  const std::string id = config.node.id;
  const auto estimate = [&buffer, id](const fb::Data& call) {
    fb::Contractor::Estimate e;
    const std::string& type = fb::get<std::string>(call, "part_type");
    const auto wanted = fb::get_or<std::int64_t>(call, "count", 1);
    e.available = buffer.free(type) >= wanted;
    if (!e.available) e.reason = id + " has " + std::to_string(buffer.free(type)) + " " + type + " free, not " + std::to_string(wanted);
    return e;
  };
  const auto describe = [&buffer](cell::Capability& c) {
    for (const auto& [type, count] : buffer.stock()) {
      cell::PartStock s;
      s.part_type(type);
      s.count(count);
      c.stock().push_back(s);
    }
  };
  node_ = std::make_unique<ResourceNode>(resource_, dds::make_participant(config.node.id, config.dds), config.node,
                                         buffer, estimate, describe);
  node_->start();
}

BufferService::~BufferService() = default;

}  // namespace services
