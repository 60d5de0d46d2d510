#include "services/node/device_block.hpp"

namespace fb {

DeviceBlock::DeviceBlock(std::string name, std::string resource_id, std::set<std::string> operations,
                         std::string initial_state)
    : BasicBlock(std::move(name), std::move(initial_state)), resource_id_(std::move(resource_id)),
      operations_(std::move(operations)) {
  declare_input("COMMAND", {"command_id", "resource_id", "operation"});
  declare_input("START", {"command_id"});
  declare_input("ORDER_ENDED", {"order_id"});
  declare_input("ORDER_ACTIVE", {"order_id"});
  declare_output("ACCEPT", {"command_id", "order_id"});
  declare_output("PROGRESS", {"progress"});
  declare_output("DONE");
  declare_output("FAIL", {"reason"});
  declare_output("REPEAT", {"command_id", "state"});
  declare_output("REFUSE", {"command_id", "reason", "order_id", "operation", "part"});
}

std::string DeviceBlock::problem_with(const Data& command) const {
  SampleCheck c(command, bounds_);
  c.text("command_id", true).text("resource_id", true).text("order_id").text("operation", true).text("part");
  c.text("part_type").text("source").text("destination").text("award").text("source_award");
  c.poses("path", 0).finite("opening").at_least("sim_time", 0);
  if (c.ok()) check(command, c);
  if (!c.ok()) return c.error();
  return authorize_ ? authorize_(command) : "";
}

void DeviceBlock::ended(const std::string& command_id, const Data& last_event) {
  constexpr std::size_t kRemembered = 1024;
  Data record = command(command_id);
  for (const auto& [key, value] : last_event) record[key] = value;
  commands_.erase(command_id);
  if (ended_.emplace(command_id, std::move(record)).second) ended_order_.push_back(command_id);
  if (ended_order_.size() > kRemembered) {
    ended_.erase(ended_order_.front());
    ended_order_.pop_front();
  }
}

const Data& DeviceBlock::command(const std::string& command_id) const {
  static const Data none;
  const auto it = commands_.find(command_id);
  return it == commands_.end() ? none : it->second;
}

void DeviceBlock::receive(const Event& event) {
  if (event.name == "COMMAND") {
    if (get<std::string>(event.data, "resource_id") != resource_id_) return;
    // Every command for this resource is accepted; one for an operation it lacks fails at
    // START with the reason, so the sender hears why.
    const std::string& id = get<std::string>(event.data, "command_id");
    if (commands_.count(id)) return;
    if (const auto done = ended_.find(id); done != ended_.end()) return emit("REPEAT", done->second);
    if (const std::string problem = problem_with(event.data); !problem.empty()) {
      ++refused_;
      last_refusal_ = get_or<std::string>(event.data, "order_id", "") + " " + id + ": " + problem;
      return emit("REFUSE", {{"command_id", id}, {"reason", problem},
                             {"order_id", get_or<std::string>(event.data, "order_id", "")},
                             {"operation", get_or<std::string>(event.data, "operation", "")},
                             {"part", get_or<std::string>(event.data, "part", "")}});
    }
    commands_[id] = event.data;
    emit("ACCEPT", {{"command_id", id}, {"order_id", get_or<std::string>(event.data, "order_id", "")}});
    return;
  }
  if (event.name == "ORDER_ENDED") {
    ended_orders_.insert(get<std::string>(event.data, "order_id"));
    order_ended(get<std::string>(event.data, "order_id"));
    return;
  }
  if (event.name == "ORDER_ACTIVE") {
    ended_orders_.erase(get<std::string>(event.data, "order_id"));
    return;
  }
  if (event.name == "START") {
    Data full = command(get<std::string>(event.data, "command_id"));
    if (full.empty()) return emit("FAIL", {{"reason", std::string("unknown command")}});
    const std::string order = get_or<std::string>(full, "order_id", "");
    if (ended_orders_.count(order)) return emit("FAIL", {{"reason", "order " + order + " has ended"}});
    if (!operations_.count(get<std::string>(full, "operation"))) {
      return emit("FAIL", {{"reason", resource_id_ + " cannot " + get<std::string>(full, "operation")}});
    }
    return BasicBlock::receive({"START", std::move(full)});
  }
  BasicBlock::receive(event);
}

std::string DeviceBlock::keep_state_in(state::CellStore& store) {
  store_ = &store;
  return recover();
}

}  // namespace fb
