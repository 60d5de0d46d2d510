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
  std::unique_lock<std::mutex> lock(mutex_);
  kept_.erase(std::remove_if(kept_.begin(), kept_.end(), [writer](const Kept& k) { return k.writer == writer; }),
              kept_.end());
  // An assertion of it under way ends first, unless it is this thread's (a reader's callback
  // during it: waiting would never end).
  if (std::this_thread::get_id() != thread_.get_id()) done_.wait(lock, [&] { return asserting_ != writer; });
}

LivelinessKeeper::~LivelinessKeeper() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    changed_.notify_all();
  }
  if (thread_.joinable()) thread_.join();
}

// One assertion at a time, with the lock released: it delivers to this process's readers on
// this thread, and their callbacks may create or delete state writers (keep, forget).
void LivelinessKeeper::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    const auto now = std::chrono::steady_clock::now();
    const auto due = std::min_element(kept_.begin(), kept_.end(), [](const Kept& a, const Kept& b) { return a.next < b.next; });
    if (due == kept_.end() || due->next > now) {
      changed_.wait_until(lock, due == kept_.end() ? now + std::chrono::hours(1) : due->next);
      continue;
    }
    due->next = now + due->period;
    asserting_ = due->writer;
    const std::function<void()> assert_alive = due->assert_alive;
    lock.unlock();
    try {
      assert_alive();
    } catch (const std::exception& e) {
      std::cerr << "could not assert a state writer's liveliness: " << e.what() << "\n";
    }
    lock.lock();
    asserting_ = nullptr;
    done_.notify_all();
  }
}

}  // namespace dds
