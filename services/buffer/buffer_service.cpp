#include "services/buffer/buffer_service.hpp"

#include "services/buffer/buffer_block.hpp"

namespace services {

BufferService::BufferService(BufferConfig config) : resource_(config.node.id, 256) {
  config.node.kind = "buffer";
  config.node.exclusive = false;
  config.node.dock = config.node.position;
  auto& buffer = resource_.add(std::make_unique<fb::BufferBlock>("buffer", config.node.id, config.stock));
  const auto can_serve = [&buffer](const std::string& operation, const std::string& part_type) {
    return operation == "give" && buffer.count(part_type) > 0;
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
                                         buffer, can_serve, describe);
  node_->start();
}

BufferService::~BufferService() = default;

}  // namespace services
