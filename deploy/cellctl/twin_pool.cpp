#include "deploy/cellctl/twin_pool.hpp"

#include <algorithm>

namespace cellctl {

TwinPool::TwinPool(std::vector<std::string> standby_argv, int size, TwinIdentities& identities,
                   std::function<void(const std::string&)> log)
    : argv_(std::move(standby_argv)), size_(static_cast<std::size_t>(std::max(size, 0))), identities_(identities),
      log_(std::move(log)) {
  tend();
}

TwinPool::~TwinPool() {
  for (auto& t : standby_) identities_.give_back(t.identity);
}

Twin TwinPool::take(const std::string& name, const std::string& order, const std::vector<std::string>& order_args) {
  std::string input;
  for (const auto& a : order_args) {
    if (a.empty() || a.find('\n') != std::string::npos) return {};  // not one line each: start it cold
    input += a + '\n';
  }
  input += '\n';
  while (!standby_.empty()) {
    Twin twin = std::move(standby_.front());
    standby_.pop_front();
    try {
      if (twin.process->poll() < 0) {
        identities_.bind(order, twin.identity);  // before the twin writes a word for the order
        if (twin.process->write_input(input)) {
          twin.process->rename(name);
          return twin;
        }
      }
    } catch (...) {
      identities_.give_back(twin.identity);
      throw;
    }
    identities_.give_back(twin.identity);
  }
  return {};
}

void TwinPool::tend() {
  const auto now = std::chrono::steady_clock::now();
  // partition, not remove_if: the ended ones stay whole (their exit, their identity).
  const auto ended = std::stable_partition(standby_.begin(), standby_.end(), [](const Twin& t) { return t.process->poll() < 0; });
  if (ended != standby_.end()) {
    // A standby twin ends only when something is wrong (killed, no cell to join): not in a loop.
    if (log_) log_("a standby twin ended (exit " + std::to_string(ended->process->poll()) + "); another in 5 s");
    not_before_ = now + std::chrono::seconds(5);
    for (auto it = ended; it != standby_.end(); ++it) identities_.give_back(it->identity);
    standby_.erase(ended, standby_.end());
  }
  while (standby_.size() < size_ && now >= not_before_) {
    const std::optional<std::string> identity = identities_.take();
    if (!identity) return;  // every identity runs a twin: one comes back when a twin ends
    try {
      standby_.push_back({std::make_unique<Process>("twin-standby", with_identity(argv_, *identity), "", "", true), *identity});
    } catch (const std::exception& e) {
      identities_.give_back(*identity);
      if (log_) log_(std::string("cannot start a standby twin: ") + e.what());
      not_before_ = now + std::chrono::seconds(5);
    }
  }
}

}  // namespace cellctl
