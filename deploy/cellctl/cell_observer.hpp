#pragma once
// What cellctl sees of a running cell over DDS: the resources (capabilities, alive or gone,
// reserved by which order), the orders (status, result), and every command event, which it
// can write as JSON lines (the event log of `cellctl run --events`).

#include <chrono>
#include <condition_variable>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "capabilities.h"
#include "orders.h"
#include "services/dds/participant.hpp"

namespace cellctl {

struct ResourceView {
  cell::Capability capability;
  bool alive = true;
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

 private:
  struct Impl;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::map<std::string, ResourceView> resources_;
  std::map<std::string, cell::OrderStatus> orders_;
  std::function<void(const cell::OrderStatus&)> on_status_;
  std::ofstream events_;
  std::size_t logged_ = 0;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cellctl
