#pragma once
// What the operator's page shows (dashboard.hpp), kept current from the running cell:
// `cellctl status`'s view (resources, orders, inventory) with each resource's command under
// way, what needs attention first, the alarms (the journal's restarts, hangs, inspections and
// failed orders; refused and aborted commands, whose and why) and the commands done, as the
// bars of a Gantt chart, and the physical cell (PhysicalScene, from cell-sim's requests and
// replies).
//
// A thread of its own builds the state when the observer hears a change (at most one build
// per kMinGap: a busy cell costs a bounded share of a core) and every kRefresh for what only
// the cell's database says. Readers wait for a newer state; none of them can slow the thread.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/cell_observer.hpp"
#include "deploy/cellctl/command_bars.hpp"
#include "deploy/cellctl/physical_scene.hpp"
#include "services/state/cell_store.hpp"

namespace cellctl {

class DashboardFeed {
 public:
  static constexpr std::chrono::milliseconds kMinGap{40};
  static constexpr std::chrono::milliseconds kRefresh{1000};
  static constexpr std::size_t kKeptAlarms = 200;
  static constexpr std::size_t kKeptBars = 20000;
  static constexpr double kBarsWindow = 3600;  // sim s of bars kept

  // Follows cell-sim's requests and replies on the observer's participant, and tells the
  // observer when the physical scene changed.
  DashboardFeed(const CellConfig& cell, CellObserver& observer);
  ~DashboardFeed();
  DashboardFeed(const DashboardFeed&) = delete;
  DashboardFeed& operator=(const DashboardFeed&) = delete;

  struct State {
    std::uint64_t seq = 0;  // grows with each state that differs; 0: none built yet
    std::string json;       // docs/dashboard.md says its fields
  };
  // The latest state once its seq passes `seen`, or after `timeout` the latest as it is.
  State wait_newer(std::uint64_t seen, std::chrono::milliseconds timeout) const;
  // The bars of commands that ended, after the bar `after` (0: all kept), as JSON objects.
  std::vector<std::pair<std::uint64_t, std::string>> bars_after(std::uint64_t after) const;
  // Ends the thread and wakes every reader (they get the state as it is).
  void stop();

 private:
  void run();
  void build();
  void take_command_events(nlohmann::json& new_alarms);
  void take_journal(nlohmann::json& new_alarms);
  nlohmann::json attention(const nlohmann::json& status) const;

  const CellConfig& cell_;
  CellObserver& observer_;
  std::unique_ptr<state::CellStore> store_;  // opened once the cell's database exists
  // The build thread's own.
  std::uint64_t events_seen_ = 0;
  long journal_seen_ = 0;
  CommandBars commands_;
  // Process -> when it last ended (Unix s). DDS still takes a killed resource for alive until
  // its lease runs out, and a restart within the lease never shows there: a resource is gone
  // from its process's end until its new process is heard.
  std::map<std::string, double> ended_at_;
  std::map<std::string, double> restarted_at_;  // process -> Unix s
  std::string last_content_;

  mutable std::mutex mutex_;
  mutable std::condition_variable newer_;
  bool stopping_ = false;
  State state_;
  std::deque<nlohmann::json> alarms_;  // newest first
  std::deque<std::pair<std::uint64_t, std::string>> bars_;
  std::deque<double> bar_ends_;  // sim s, beside bars_
  std::uint64_t bar_seq_ = 0;
  PhysicalScene scene_;
  struct SceneReaders;
  std::unique_ptr<SceneReaders> scene_readers_;  // after scene_: they end before it
  std::thread thread_;
};

}  // namespace cellctl
