#include "services/dds/liveliness_keeper.hpp"

#include <algorithm>
#include <exception>
#include <iostream>

namespace dds {

LivelinessKeeper& LivelinessKeeper::of_this_process() {
  static LivelinessKeeper keeper;
  return keeper;
}

void LivelinessKeeper::keep(const void* writer, std::chrono::milliseconds period, std::function<void()> assert_alive) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!thread_.joinable()) thread_ = std::thread([this] { run(); });  // first: if it throws, nothing is kept
  period = std::max(period, std::chrono::milliseconds(1));
  kept_.push_back({writer, period, std::move(assert_alive), std::chrono::steady_clock::now() + period});
  changed_.notify_all();
}

void LivelinessKeeper::forget(const void* writer) {
  std::lock_guard<std::mutex> lock(mutex_);  // an assertion under way ends first: it holds the lock
  kept_.erase(std::remove_if(kept_.begin(), kept_.end(), [writer](const Kept& k) { return k.writer == writer; }),
              kept_.end());
}

LivelinessKeeper::~LivelinessKeeper() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    changed_.notify_all();
  }
  if (thread_.joinable()) thread_.join();
}

void LivelinessKeeper::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    const auto now = std::chrono::steady_clock::now();
    auto next = now + std::chrono::hours(1);
    for (Kept& k : kept_) {
      if (k.next <= now) {
        // To a reader in this process it is delivered on this thread, whose callbacks may run
        // here (hence keep and forget never from a callback).
        try {
          k.assert_alive();
        } catch (const std::exception& e) {
          std::cerr << "could not assert a state writer's liveliness: " << e.what() << "\n";
        }
        k.next = now + k.period;
      }
      next = std::min(next, k.next);
    }
    changed_.wait_until(lock, next);
  }
}

}  // namespace dds
