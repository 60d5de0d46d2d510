#include "services/blocks/command_lifecycle.hpp"

#include <algorithm>

namespace fb {

CommandLifecycle::CommandLifecycle(std::string name, WhenBusy when_busy) : BasicBlock(std::move(name), "IDLE") {
  declare_input("COMMAND", {"command_id"});  // and its order_id, where it has one
  declare_input("PROGRESS", {"progress"});
  declare_input("DONE");
  declare_input("FAIL", {"reason"});
  declare_input("CANCEL", {"command_id"});
  declare_input("STOPPED");
  declare_output("ACCEPTED", {"command_id"});
  declare_output("START", {"command_id"});
  declare_output("EXECUTING", {"command_id", "progress"});
  declare_output("SUCCEEDED", {"command_id"});
  declare_output("ABORTED", {"command_id", "reason"});
  declare_output("CANCELING", {"command_id"});
  declare_output("STOP", {"command_id"});
  declare_output("CANCELED", {"command_id"});
  declare_output("REJECTED", {"command_id", "reason"});
  declare_output("IDLE");

  const auto is_current = [this](const Data& d) {
    return get<std::string>(d, "command_id") == command_ && from_its_order(d);
  };
  const auto queue_is_empty = [this](const Data&) { return queue_.empty(); };

  transition("IDLE", "COMMAND", "EXECUTING", [this](const Data& d) {
    command_ = get<std::string>(d, "command_id");
    order_of_[command_] = get_or<std::string>(d, "order_id", "");
    emit("ACCEPTED", with_id({}));
    emit("START", with_id({}));
  });
  transition("EXECUTING", "PROGRESS", "EXECUTING", [this](const Data& d) { emit("EXECUTING", with_id(d)); });
  // An outcome ends the command; the next queued one starts at once.
  for (const char* state : {"EXECUTING", "CANCELING"}) {
    transition(state, "DONE", "IDLE", [this](const Data& d) {
      emit("SUCCEEDED", with_id(d));
      order_of_.erase(command_);
      emit("IDLE");
    }, queue_is_empty);
    transition(state, "DONE", "EXECUTING", [this](const Data& d) {
      emit("SUCCEEDED", with_id(d));
      start_next();
    });
    transition(state, "FAIL", "IDLE", [this](const Data& d) {
      emit("ABORTED", with_id(d));
      order_of_.erase(command_);
      emit("IDLE");
    }, queue_is_empty);
    transition(state, "FAIL", "EXECUTING", [this](const Data& d) {
      emit("ABORTED", with_id(d));
      start_next();
    });
  }
  transition("EXECUTING", "CANCEL", "CANCELING", [this](const Data&) {
    emit("CANCELING", with_id({}));
    emit("STOP", with_id({}));
  }, is_current);
  // A command still waiting in the queue is simply taken out.
  const auto is_queued = [this](const Data& d) {
    return std::find(queue_.begin(), queue_.end(), get<std::string>(d, "command_id")) != queue_.end() && from_its_order(d);
  };
  for (const char* busy : {"EXECUTING", "CANCELING"}) {
    transition(busy, "CANCEL", busy, [this](const Data& d) {
      const std::string& id = get<std::string>(d, "command_id");
      queue_.erase(std::find(queue_.begin(), queue_.end(), id));
      order_of_.erase(id);
      emit("CANCELED", {{"command_id", id}});
    }, is_queued);
  }
  transition("CANCELING", "STOPPED", "IDLE", [this](const Data&) {
    emit("CANCELED", with_id({}));
    order_of_.erase(command_);
    emit("IDLE");
  }, queue_is_empty);
  transition("CANCELING", "STOPPED", "EXECUTING", [this](const Data&) {
    emit("CANCELED", with_id({}));
    start_next();
  });
  for (const char* busy : {"EXECUTING", "CANCELING"}) {
    if (when_busy == WhenBusy::queue) {
      transition(busy, "COMMAND", busy, [this](const Data& d) {
        queue_.push_back(get<std::string>(d, "command_id"));
        order_of_[queue_.back()] = get_or<std::string>(d, "order_id", "");
        emit("ACCEPTED", {{"command_id", queue_.back()}});
      });
    } else {
      transition(busy, "COMMAND", busy, [this](const Data& d) {
        emit("REJECTED", {{"command_id", get<std::string>(d, "command_id")}, {"reason", "busy with " + command_}});
      });
    }
  }
}

bool CommandLifecycle::from_its_order(const Data& cancel) const {
  const auto it = order_of_.find(get<std::string>(cancel, "command_id"));
  return it != order_of_.end() && it->second == get_or<std::string>(cancel, "order_id", "");
}

Data CommandLifecycle::with_id(Data data) const {
  data["command_id"] = command_;
  return data;
}

void CommandLifecycle::start_next() {
  order_of_.erase(command_);
  command_ = queue_.front();
  queue_.pop_front();
  emit("EXECUTING", with_id({{"progress", 0.0}}));
  emit("START", with_id({}));
}

}  // namespace fb
