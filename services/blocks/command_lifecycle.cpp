#include "services/blocks/command_lifecycle.hpp"

namespace fb {

CommandLifecycle::CommandLifecycle(std::string name) : BasicBlock(std::move(name), "IDLE") {
  declare_input("COMMAND", {"command_id"});
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

  const auto id = [this] { return Data{{"command_id", command_}}; };
  const auto is_current = [this](const Data& d) { return get<std::string>(d, "command_id") == command_; };

  transition("IDLE", "COMMAND", "EXECUTING", [this, id](const Data& d) {
    command_ = get<std::string>(d, "command_id");
    emit("ACCEPTED", id());
    emit("START", id());
  });
  transition("EXECUTING", "PROGRESS", "EXECUTING", [this](const Data& d) {
    emit("EXECUTING", {{"command_id", command_}, {"progress", get<double>(d, "progress")}});
  });
  transition("EXECUTING", "DONE", "IDLE", [this, id](const Data&) { emit("SUCCEEDED", id()); });
  transition("EXECUTING", "FAIL", "IDLE", [this](const Data& d) {
    emit("ABORTED", {{"command_id", command_}, {"reason", get<std::string>(d, "reason")}});
  });
  transition("EXECUTING", "CANCEL", "CANCELING", [this, id](const Data&) {
    emit("CANCELING", id());
    emit("STOP", id());
  }, is_current);
  transition("CANCELING", "STOPPED", "IDLE", [this, id](const Data&) { emit("CANCELED", id()); });
  // The device may finish or fail before it could stop: that outcome stands.
  transition("CANCELING", "DONE", "IDLE", [this, id](const Data&) { emit("SUCCEEDED", id()); });
  transition("CANCELING", "FAIL", "IDLE", [this](const Data& d) {
    emit("ABORTED", {{"command_id", command_}, {"reason", get<std::string>(d, "reason")}});
  });
  // One command at a time: another one is refused, never queued behind the current one.
  for (const char* busy : {"EXECUTING", "CANCELING"}) {
    transition(busy, "COMMAND", busy, [this](const Data& d) { reject(d); });
  }
}

void CommandLifecycle::reject(const Data& data) {
  emit("REJECTED", {{"command_id", get<std::string>(data, "command_id")}, {"reason", "busy with " + command_}});
}

}  // namespace fb
