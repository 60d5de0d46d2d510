#pragma once
// Runs resources until a flag (set by a signal handler) turns false: each resource on a thread
// of its own, delivering its events one at a time.

#include <chrono>
#include <sys/prctl.h>

#include <atomic>
#include <csignal>
#include <thread>
#include <vector>

#include "services/runtime/resource.hpp"

namespace services {

// The process gets SIGTERM when the process that started it ends, however it ends: a cell or
// a twin never outlives the cellctl (or test) that started it.
inline void stop_with_parent() { ::prctl(PR_SET_PDEATHSIG, SIGTERM); }

inline void run_until_stopped(const std::vector<fb::Resource*>& resources, const std::atomic<bool>& running) {
  std::vector<std::thread> threads;
  for (fb::Resource* r : resources) {
    threads.emplace_back([r, &running] {
      while (running) r->wait_and_run_one(std::chrono::milliseconds(100));
    });
  }
  for (auto& t : threads) t.join();
}

}  // namespace services
