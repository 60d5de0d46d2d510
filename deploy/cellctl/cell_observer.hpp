#pragma once
// What cellctl sees of a running cell over DDS: the resources (capabilities, alive or gone,
// reserved by which order), the orders (status, result), and every command event, which it
// can write as JSON lines (the event log of `cellctl run --events`).

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "capabilities.h"
#include "deploy/cellctl/command_bars.hpp"
#include "orders.h"
#include "services/dds/participant.hpp"

namespace cellctl {

struct ResourceView {
  cell::Capability capability;
  bool alive = true;
  std::chrono::system_clock::time_point heard_at;  // its last capability
};

class CellObserver {
 public:
  explicit CellObserver(const dds::ParticipantSettings& settings);
  ~CellObserver();

  // Its participant, for other endpoints of the same process (the remote order desk).
  const dds::ParticipantPtr& participant() const;

  // Writes every command event (and every delivery) as one JSON line to `file` from now on.
  void log_events_to(const std::string& file);
  // Called with each new order status (on a DDS thread).
  void on_status(std::function<void(const cell::OrderStatus&)> callback);

  // Waits until every id has published its capability; the ids still missing.
  std::vector<std::string> wait_for_resources(const std::vector<std::string>& ids, std::chrono::milliseconds timeout);
  std::map<std::string, ResourceView> resources() const;
  std::map<std::string, cell::OrderStatus> orders() const;
  std::size_t events_logged() const;
  double sim_now() const;  // the cell's sim time, s (0 before cell-sim's clock is heard)

  // The cell's version grows with every capability, order status and command event heard,
  // and with note_change(): a change DDS does not carry (a process ended: the journal says so).
  void note_change();
  // Waits until the version passes `seen` (0 at first); the version then (`seen` after the
  // timeout).
  std::uint64_t wait_for_change(std::uint64_t seen, std::chrono::milliseconds timeout) const;
  // When the change that made the current version was heard.
  std::chrono::system_clock::time_point changed_at() const;
  // The command events heard after `after` (a CommandHeard::seq), oldest first; the observer
  // keeps the last kKeptCommandEvents.
  std::vector<CommandHeard> command_events_after(std::uint64_t after) const;
  static constexpr std::size_t kKeptCommandEvents = 20000;

 private:
  struct Impl;
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::uint64_t version_ = 0;
  std::chrono::system_clock::time_point changed_at_{};
  std::deque<CommandHeard> command_events_;
  std::uint64_t command_seq_ = 0;
  std::map<std::string, ResourceView> resources_;
  std::map<std::string, cell::OrderStatus> orders_;
  std::function<void(const cell::OrderStatus&)> on_status_;
  std::ofstream events_;
  std::size_t logged_ = 0;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cellctl
