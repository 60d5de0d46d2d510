#pragma once
// The cell's work as a Gantt chart draws it, from the command events cellctl hears: a bar per
// command, from its start to its end. A command starts when an idle resource accepts it, or,
// when it waited in the resource's queue, at its first EXECUTING; it ends SUCCEEDED, ABORTED,
// CANCELED or REJECTED. One that never ran makes no bar.

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "commands.h"

namespace cellctl {

// One command event as cellctl heard it.
struct CommandHeard {
  std::uint64_t seq = 0;  // 1, 2, ... in the order heard
  std::string resource, order, operation, part, command;
  cell::CommandState state = cell::ACCEPTED;
  std::string reason;
  double sim_time = 0;
  std::chrono::system_clock::time_point heard_at;
};

struct CommandBar {
  std::string resource, order, operation, part;
  double start = 0, end = 0;  // sim s
  cell::CommandState state = cell::SUCCEEDED;
};

class CommandBars {
 public:
  struct Running {
    std::string resource, order, operation, part;
    double since = 0;      // sim s
    bool started = false;  // false: waiting in the resource's queue
  };

  // The bar the event ends, if it ends one that ran.
  std::optional<CommandBar> take(const CommandHeard& e);
  // The commands of the resources `lost` says ended with their process: no event will end them.
  void lose(const std::function<bool(const std::string& resource)>& lost);
  // Resource -> the command it runs now.
  std::map<std::string, Running> under_way() const;

 private:
  std::map<std::string, Running> commands_;  // command id -> (accepted, not ended)
};

}  // namespace cellctl
