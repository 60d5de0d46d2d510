#include "deploy/cellctl/supervisor.hpp"

#include <algorithm>

namespace cellctl {

Supervisor::Supervisor(std::vector<ProcessSpec> specs, RestartPolicy policy, Log log)
    : policy_(policy), log_(std::move(log)) {
  heartbeats_.name_to_children();
  for (auto& spec : specs) {
    Child child{std::move(spec), nullptr, {}, {}, 0, std::chrono::steady_clock::now()};
    child.process = std::make_unique<Process>(child.spec.name, child.spec.argv);
    heartbeats_.watch(child.process->pid());
    children_.push_back(std::move(child));
  }
}

Supervisor::~Supervisor() { stop(); }

std::string Supervisor::tend() {
  const auto now = std::chrono::steady_clock::now();
  for (Child& c : children_) {
    if (c.process) {
      const int code = c.process->poll();
      if (code < 0) continue;
      heartbeats_.forget(c.process->pid());
      c.process.reset();
      c.ends.push_back(now);
      while (!c.ends.empty() && now - c.ends.front() > policy_.window) c.ends.pop_front();
      if (static_cast<int>(c.ends.size()) > policy_.limit) {
        return c.spec.name + " ended " + std::to_string(c.ends.size()) + " times within " +
               std::to_string(policy_.window.count()) + " s, last with exit " + std::to_string(code);
      }
      // Backoff doubles with each end inside the window: a process that dies at once again
      // is not restarted in a tight loop.
      auto backoff = policy_.first_backoff * (1 << std::min<int>(static_cast<int>(c.ends.size()) - 1, 10));
      backoff = std::min(backoff, policy_.max_backoff);
      c.restart_at = now + backoff;
      log_(c.spec.name, "ended", c.spec.name + " ended (exit " + std::to_string(code) + "); restarting it in " +
           std::to_string(backoff.count()) + " ms");
      if (c.spec.others_depend) restart_dependents(c);
    } else if (now >= c.restart_at) {
      try {
        c.process = std::make_unique<Process>(c.spec.name, c.spec.argv);
        heartbeats_.watch(c.process->pid());
        c.heard_at = std::chrono::steady_clock::now();
        ++c.restarts;
        log_(c.spec.name, "restarted", c.spec.name + " restarted (pid " + std::to_string(c.process->pid()) + ", restart " +
             std::to_string(c.restarts) + ")");
      } catch (const std::exception& e) {
        return c.spec.name + " cannot be started again: " + e.what();
      }
    }
  }
  return "";
}

std::vector<std::string> Supervisor::end_unheard(const std::set<std::string>& heard,
                                                 std::chrono::steady_clock::duration silence) {
  const auto now = std::chrono::steady_clock::now();
  const auto seconds_since = [now](std::chrono::steady_clock::time_point t) {
    return std::to_string(std::chrono::duration_cast<std::chrono::seconds>(now - t).count());
  };
  std::vector<std::string> ended;
  const auto stopped = heartbeats_.stopped(silence);
  for (Child& c : children_) {
    if (!c.process) continue;
    std::string why;  // "" while it is not hung
    if (const auto beat = stopped.find(c.process->pid()); beat != stopped.end()) {
      why = beat->second;
    } else if (!c.spec.resources.empty()) {
      const bool all_heard = std::all_of(c.spec.resources.begin(), c.spec.resources.end(),
                                         [&heard](const std::string& r) { return heard.count(r) > 0; });
      if (all_heard) c.heard_at = now;
      if (!all_heard && now - c.heard_at >= silence) why = "has not been heard on DDS for " + seconds_since(c.heard_at) + " s (hung?)";
    }
    if (why.empty()) continue;
    log_(c.spec.name, "unheard", c.spec.name + " runs but " + why + "; ending it to restart it");
    c.process->stop(std::chrono::seconds(2));  // tend() finds it ended
    ended.push_back(c.spec.name);
  }
  return ended;
}

bool Supervisor::runs(const std::string& resource) const {
  return std::any_of(children_.begin(), children_.end(), [&resource](const Child& c) {
    return std::find(c.spec.resources.begin(), c.spec.resources.end(), resource) != c.spec.resources.end();
  });
}

// The others' state lived in the process that ended (their bodies in cell-sim's world): they
// start again after it, and these ends are not theirs to count.
void Supervisor::restart_dependents(const Child& hub) {
  std::vector<Process*> running;
  for (Child& c : children_) {
    if (&c == &hub || !c.process) continue;
    running.push_back(c.process.get());
    c.restart_at = hub.restart_at + std::chrono::milliseconds(100);
  }
  log_(hub.spec.name, "restarting all", "the other processes of the cell depend on " + hub.spec.name +
                                            "; restarting them with it");
  stop_all(running);
  for (Child& c : children_) {
    if (&c == &hub || !c.process) continue;
    heartbeats_.forget(c.process->pid());
    c.process.reset();
  }
}

void Supervisor::stop() {
  std::vector<Process*> all;
  for (Child& c : children_) {
    if (c.process) all.push_back(c.process.get());
  }
  stop_all(all);
  for (Child& c : children_) c.process.reset();
}

}  // namespace cellctl
