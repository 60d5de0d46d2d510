#include "services/dds/liveliness_keeper.hpp"

#include <algorithm>

#include <fastdds/dds/publisher/DataWriter.hpp>

namespace dds {

LivelinessKeeper& LivelinessKeeper::of_this_process() {
  static LivelinessKeeper keeper;
  return keeper;
}

void LivelinessKeeper::keep(eprosima::fastdds::dds::DataWriter* writer, std::chrono::milliseconds period) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!thread_.joinable()) thread_ = std::thread([this] { run(); });  // first: if it throws, nothing is kept
  period = std::max(period, std::chrono::milliseconds(1));
  kept_.push_back({writer, period, std::chrono::steady_clock::now() + period});
  changed_.notify_all();
}

void LivelinessKeeper::forget(eprosima::fastdds::dds::DataWriter* writer) {
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
        // A heartbeat to its readers; to a reader in this process it is delivered on this
        // thread, whose callbacks may run here (hence keep and forget never from a callback).
        k.writer->assert_liveliness();
        k.next = now + k.period;
      }
      next = std::min(next, k.next);
    }
    changed_.wait_until(lock, next);
  }
}

}  // namespace dds
