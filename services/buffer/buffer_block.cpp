#include "services/buffer/buffer_block.hpp"

#include "services/state/cell_store.hpp"

namespace fb {

BufferBlock::BufferBlock(std::string name, std::string resource_id, std::map<std::string, int> stock)
    : DeviceBlock(std::move(name), std::move(resource_id), {"give"}), stock_(std::move(stock)) {
  declare_input("AWARDED", {"order_id", "part_type", "count"});
  declare_output("CAPABILITY");
  transition("READY", "AWARDED", "READY", [this](const Data& d) {
    kept_[get<std::string>(d, "order_id")][get<std::string>(d, "part_type")] +=
        static_cast<int>(get_or<std::int64_t>(d, "count", 1));
  });
  transition("READY", "START", "READY", [this](const Data& d) {
    // A command names the type it wants; older senders put it in "part".
    std::string type = get_or<std::string>(d, "part_type", "");
    if (type.empty()) type = get<std::string>(d, "part");
    const std::string order = get_or<std::string>(d, "order_id", "");
    int& kept = kept_[order][type];
    if (kept == 0 && free(type) == 0) {
      return emit("FAIL", {{"reason", "buffer " + this->resource_id() + " has no " + type +
                                           (order.empty() ? "" : " free for order " + order)}});
    }
    // The durable stock first: a part counted out in memory only would come back with a restart.
    if (store()) {
      store()->give(this->resource_id(), type, order, get_or<std::string>(d, "part", ""),
                    get_or<std::string>(d, "destination", ""));
    }
    if (kept > 0) --kept;
    --stock_[type];
    emit("DONE");
    emit("CAPABILITY");
  });
}

int BufferBlock::count(const std::string& part_type) const {
  const auto it = stock_.find(part_type);
  return it == stock_.end() ? 0 : it->second;
}

int BufferBlock::free(const std::string& part_type) const {
  int n = count(part_type);
  for (const auto& [order, types] : kept_) {
    const auto it = types.find(part_type);
    if (it != types.end()) n -= it->second;
  }
  return n;
}

void BufferBlock::check(const Data& command, SampleCheck& c) const {
  if (get<std::string>(command, "operation") == "give" && get_or<std::string>(command, "part", "").empty()) {
    c.text("part_type", true);
  }
}

std::string BufferBlock::recover() {
  const std::map<std::string, int> before = stock_;
  stock_ = store()->open_buffer(resource_id(), stock_);
  return stock_ == before ? "" : "stock as stored, not as the deployment file gives it";
}

void BufferBlock::order_ended(const std::string& order) { kept_.erase(order); }

}  // namespace fb
