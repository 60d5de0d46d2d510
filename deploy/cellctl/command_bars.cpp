#include "deploy/cellctl/command_bars.hpp"

#include <algorithm>

namespace cellctl {

std::optional<CommandBar> CommandBars::take(const CommandHeard& e) {
  const Running now{e.resource, e.order, e.operation, e.part, e.sim_time, true};
  if (e.state == cell::ACCEPTED) {
    const bool busy = std::any_of(commands_.begin(), commands_.end(),
                                  [&](const auto& c) { return c.second.started && c.second.resource == e.resource; });
    Running accepted = now;
    accepted.started = !busy;
    commands_.try_emplace(e.command, accepted);
    return std::nullopt;
  }
  if (e.state == cell::EXECUTING) {
    Running& r = commands_[e.command];
    if (!r.started) r = now;
    return std::nullopt;
  }
  if (e.state == cell::CANCELING) return std::nullopt;
  const auto it = commands_.find(e.command);
  if (it == commands_.end()) return std::nullopt;
  std::optional<CommandBar> bar;
  if (it->second.started) bar = CommandBar{e.resource, e.order, e.operation, e.part, it->second.since, e.sim_time, e.state};
  commands_.erase(it);
  return bar;
}

void CommandBars::lose(const std::function<bool(const std::string& resource)>& lost) {
  for (auto it = commands_.begin(); it != commands_.end();) it = lost(it->second.resource) ? commands_.erase(it) : std::next(it);
}

std::map<std::string, CommandBars::Running> CommandBars::under_way() const {
  std::map<std::string, Running> out;
  for (const auto& [command, r] : commands_) {
    if (r.started) out[r.resource] = r;
  }
  return out;
}

}  // namespace cellctl
