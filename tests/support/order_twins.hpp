#pragma once
// Which process is an order's twin. cellctl up's desk journals "twin started" with the
// twin's pid: a standby twin (deploy/cellctl/twin_pool.hpp) has no --order on its command
// line to find it by.

#include <sys/types.h>

#include <string>

#include "services/state/cell_store.hpp"

namespace test {

// The pid in a "twin started" entry's detail ("attempt 2, pid 1234, standing by"), or 0.
inline pid_t started_pid(const state::JournalEntry& e) {
  const auto at = e.detail.find("pid ");
  if (e.event != "twin started" || at == std::string::npos) return 0;
  return static_cast<pid_t>(std::atol(e.detail.c_str() + at + 4));
}

// The twin the desk started last for `order`, or 0.
inline pid_t twin_of(const state::CellStore& store, const std::string& order) {
  pid_t pid = 0;
  for (const auto& e : store.journal_since(0)) {
    if (e.order == order && started_pid(e) > 0) pid = started_pid(e);
  }
  return pid;
}

// The order whose twin `pid` is, or "".
inline std::string order_of_twin(const state::CellStore& store, pid_t pid) {
  std::string order;
  for (const auto& e : store.journal_since(0)) {
    if (started_pid(e) == pid) order = e.order;
  }
  return order;
}

}  // namespace test
