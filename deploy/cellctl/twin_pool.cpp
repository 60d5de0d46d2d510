#include "deploy/cellctl/twin_pool.hpp"

#include <algorithm>

namespace cellctl {

TwinPool::TwinPool(std::vector<std::string> standby_argv, int size, std::function<void(const std::string&)> log)
    : argv_(std::move(standby_argv)), size_(static_cast<std::size_t>(std::max(size, 0))), log_(std::move(log)) {
  tend();
}

std::unique_ptr<Process> TwinPool::take(const std::string& name, const std::vector<std::string>& order_args) {
  std::string input;
  for (const auto& a : order_args) {
    if (a.empty() || a.find('\n') != std::string::npos) return nullptr;  // not one line each: start it cold
    input += a + '\n';
  }
  input += '\n';
  while (!standby_.empty()) {
    auto twin = std::move(standby_.front());
    standby_.pop_front();
    if (twin->poll() < 0 && twin->write_input(input)) {
      twin->rename(name);
      return twin;
    }
  }
  return nullptr;
}

void TwinPool::tend() {
  const auto now = std::chrono::steady_clock::now();
  const auto ended = std::remove_if(standby_.begin(), standby_.end(), [](const auto& t) { return t->poll() >= 0; });
  if (ended != standby_.end()) {
    // A standby twin ends only when something is wrong (killed, no cell to join): not in a loop.
    if (log_) log_("a standby twin ended (exit " + std::to_string((*ended)->poll()) + "); another in 5 s");
    not_before_ = now + std::chrono::seconds(5);
    standby_.erase(ended, standby_.end());
  }
  while (standby_.size() < size_ && now >= not_before_) {
    try {
      standby_.push_back(std::make_unique<Process>("twin-standby", argv_, "", "", true));
    } catch (const std::exception& e) {
      if (log_) log_(std::string("cannot start a standby twin: ") + e.what());
      not_before_ = now + std::chrono::seconds(5);
    }
  }
}

}  // namespace cellctl
