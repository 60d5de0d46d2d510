#pragma once
// Keeps a cell's processes running, as systemd's Restart=on-failure or ROS 2 launch's
// respawn do: a process that ends is started again with the same arguments after a backoff
// (0.5 s, doubling up to 8 s). A process that ends more than `limit` times within `window`
// is given up on: the cell cannot heal itself, and the operator is told why. Like systemd's
// WatchdogSec, a process that runs but is not heard is ended, and so restarted too.

#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/heartbeat_socket.hpp"
#include "deploy/cellctl/processes.hpp"

namespace cellctl {

class Supervisor {
 public:
  // What happened to a process ("ended", "restarted"), and the sentence for the operator.
  using Log = std::function<void(const std::string& process, const std::string& event, const std::string& message)>;
  // Starts every process of the specs, in order, with NOTIFY_SOCKET naming its heartbeat
  // socket (set in this process's environment: what it starts later beats there too).
  Supervisor(std::vector<ProcessSpec> specs, RestartPolicy policy, Log log);
  ~Supervisor();

  // Restarts what ended and is due; returns "" while the cell can go on, otherwise why not
  // ("buffer-1 ended 6 times within 60 s, last with exit 134").
  std::string tend();
  // Ends each running process one of whose resources is not in `heard` (those alive on DDS
  // now) and has not been since `silence` ago, or since the process started: a hung process
  // (seen: a buffer silent on DDS from its start, under ThreadSanitizer, that the whole cell
  // waited for). So too a process that beat its heartbeat (services::Heartbeat) and has not
  // for `silence`: its DDS participant may look alive while its own loop is stuck (cell-sim
  // was, in a deadlock inside Fast DDS). tend() restarts it as one that died. Returns the
  // names of those it ended.
  std::vector<std::string> end_unheard(const std::set<std::string>& heard, std::chrono::steady_clock::duration silence);
  // The socket its children beat on, and what else it starts (the desk's twins).
  HeartbeatSocket& heartbeats() { return heartbeats_; }
  // Whether a process of this supervisor publishes the resource.
  bool runs(const std::string& resource) const;
  void stop();

 private:
  struct Child {
    ProcessSpec spec;
    std::unique_ptr<Process> process;  // null while it waits for its restart
    std::deque<std::chrono::steady_clock::time_point> ends;
    std::chrono::steady_clock::time_point restart_at;
    int restarts = 0;
    std::chrono::steady_clock::time_point heard_at;  // its start, or when all its resources were last heard
  };
  void restart_dependents(const Child& hub);

  RestartPolicy policy_;
  Log log_;
  HeartbeatSocket heartbeats_;
  std::vector<Child> children_;
};

}  // namespace cellctl
