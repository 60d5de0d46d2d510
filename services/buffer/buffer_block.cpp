#include "services/buffer/buffer_block.hpp"

#include "services/state/cell_store.hpp"

namespace fb {

BufferBlock::BufferBlock(std::string name, std::string resource_id, std::map<std::string, int> stock)
    : DeviceBlock(std::move(name), std::move(resource_id), {"give"}), stock_(std::move(stock)) {
  declare_input("AWARDED", {"order_id", "part_type", "count"});
  declare_output("CAPABILITY");
  transition("READY", "AWARDED", "READY", [this](const Data& d) {
    const std::string& order = get<std::string>(d, "order_id");
    const std::string& type = get<std::string>(d, "part_type");
    const int count = static_cast<int>(get_or<std::int64_t>(d, "count", 1));
    if (store()) store()->keep(this->resource_id(), order, type, count);
    kept_[order][type] += count;
  });
  transition("READY", "START", "READY", [this](const Data& d) {
    // A command names the type it wants; older senders put it in "part".
    std::string type = get_or<std::string>(d, "part_type", "");
    if (type.empty()) type = get<std::string>(d, "part");
    const std::string order = get_or<std::string>(d, "order_id", "");
    const std::string part = get_or<std::string>(d, "part", ""), destination = get_or<std::string>(d, "destination", "");
    // A give that the process before this one did, and whose answer was lost with it, is
    // answered again, not done twice.
    if (store() && store()->given(this->resource_id(), order, part, destination)) return emit("DONE");
    int& kept = kept_[order][type];
    if (kept == 0 && free(type) == 0) {
      return emit("FAIL", {{"reason", "buffer " + this->resource_id() + " has no " + type +
                                           (order.empty() ? "" : " free for order " + order)}});
    }
    // The durable stock first: a part counted out in memory only would come back with a restart.
    if (store()) store()->give(this->resource_id(), type, order, part, destination);
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
  if (get<std::string>(command, "operation") != "give") return;
  if (get_or<std::string>(command, "part", "").empty()) c.text("part_type", true);
  // The durable state records who took the part: a robot that restarts gives back what its
  // record says it carried. (That the sender is that robot, DDS-Security proves: its partition,
  // NodeConfig::commanded_by_destination.)
  c.text("destination", true);
}

std::string BufferBlock::recover() {
  const std::map<std::string, int> before = stock_;
  // Counted out, never answered: the give is answered ABORTED (ResourceNode), so its part is
  // back in the stock before the stock is read.
  std::string undone;
  for (const auto& p : store()->undo_unanswered_gives(resource_id())) {
    undone += (undone.empty() ? "" : ", ") + p.part + " (" + p.part_type + ")";
  }
  stock_ = store()->open_buffer(resource_id(), stock_);
  // What it kept for orders that ended while it was down goes back to the free stock.
  kept_ = store()->kept(resource_id());
  for (const auto& o : store()->orders()) {
    if (o.ended() && kept_.erase(o.order)) store()->unkeep(resource_id(), o.order);
  }
  std::string changed = stock_ == before ? "" : "stock as stored, not as the deployment file gives it";
  if (!kept_.empty()) changed += std::string(changed.empty() ? "" : "; ") + std::to_string(kept_.size()) + " orders' parts kept";
  if (!undone.empty()) changed += std::string(changed.empty() ? "" : "; ") + undone + " back in stock: given, never answered";
  return changed;
}

void BufferBlock::order_ended(const std::string& order) {
  kept_.erase(order);
  if (store()) store()->unkeep(resource_id(), order);
}

}  // namespace fb
