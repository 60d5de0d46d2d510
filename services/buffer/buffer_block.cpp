#include "services/buffer/buffer_block.hpp"

namespace fb {

BufferBlock::BufferBlock(std::string name, std::string resource_id, std::map<std::string, int> stock)
    : BasicBlock(std::move(name), "READY"), resource_id_(std::move(resource_id)), stock_(std::move(stock)) {
  declare_input("COMMAND", {"command_id", "resource_id", "operation", "part"});
  declare_input("START", {"command_id"});
  declare_output("ACCEPT", {"command_id"});
  declare_output("DONE");
  declare_output("FAIL", {"reason"});
  declare_output("STOCK");

  const auto for_me = [this](const Data& d) {
    return get<std::string>(d, "resource_id") == resource_id_ && get<std::string>(d, "operation") == "give";
  };
  transition("READY", "COMMAND", "READY", [this](const Data& d) {
    const std::string& id = get<std::string>(d, "command_id");
    part_of_command_[id] = get<std::string>(d, "part");
    emit("ACCEPT", {{"command_id", id}});
  }, for_me);
  transition("READY", "START", "READY", [this](const Data& d) {
    const auto it = part_of_command_.find(get<std::string>(d, "command_id"));
    if (it == part_of_command_.end()) return emit("FAIL", {{"reason", std::string("unknown command")}});
    const std::string part = it->second;
    part_of_command_.erase(it);
    auto stock = stock_.find(part);
    if (stock == stock_.end() || stock->second == 0) {
      return emit("FAIL", {{"reason", "buffer " + resource_id_ + " has no " + part}});
    }
    --stock->second;
    emit("DONE");
    emit("STOCK");
  });
}

}  // namespace fb
