#include "services/buffer/buffer_block.hpp"

namespace fb {

BufferBlock::BufferBlock(std::string name, std::string resource_id, std::map<std::string, int> stock)
    : DeviceBlock(std::move(name), std::move(resource_id), {"give"}), stock_(std::move(stock)) {
  declare_output("CAPABILITY");
  transition("READY", "START", "READY", [this](const Data& d) {
    // A command names the type it wants; older senders put it in "part".
    std::string type = get_or<std::string>(d, "part_type", "");
    if (type.empty()) type = get<std::string>(d, "part");
    if (count(type) == 0) return emit("FAIL", {{"reason", "buffer " + this->resource_id() + " has no " + type}});
    --stock_[type];
    emit("DONE");
    emit("CAPABILITY");
  });
}

int BufferBlock::count(const std::string& part_type) const {
  const auto it = stock_.find(part_type);
  return it == stock_.end() ? 0 : it->second;
}

}  // namespace fb
