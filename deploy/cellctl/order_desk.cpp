#include "deploy/cellctl/order_desk.hpp"

#include <vector>

namespace cellctl {

OrderDesk::OrderDesk(const CellConfig& cell, state::CellStore& store, std::function<void(const std::string&)> log,
                     int max_attempts)
    : cell_(cell), store_(store), log_(std::move(log)), max_attempts_(max_attempts) {}

OrderDesk::~OrderDesk() { interrupt_all(); }

void OrderDesk::tend() {
  const auto now = std::chrono::steady_clock::now();
  std::map<std::string, state::OrderRecord> orders;
  for (auto& o : store_.orders()) orders[o.order] = o;

  for (auto it = twins_.begin(); it != twins_.end();) {
    const int code = it->second->poll();
    if (code < 0) {
      ++it;
      continue;
    }
    const auto o = orders.find(it->first);
    if (o != orders.end() && !o->second.ended()) {
      log_("the twin of order " + it->first + " ended (exit " + std::to_string(code) +
           ") before its order did; starting it again in 1 s");
      store_.journal("twin-" + it->first, "ended", it->first, "exit " + std::to_string(code));
      not_before_[it->first] = now + std::chrono::seconds(1);
    }
    it = twins_.erase(it);
  }

  for (const auto& [id, o] : orders) {
    if (o.ended() || twins_.count(id) || o.product.empty()) continue;  // no product: not the desk's order
    if (const auto wait = not_before_.find(id); wait != not_before_.end() && now < wait->second) continue;
    const int attempt = store_.count_attempt(id);
    if (attempt > max_attempts_) {
      const std::string why = "its twin ended " + std::to_string(attempt - 1) + " times before the order did" +
                              (o.reason.empty() ? "" : "; last: " + o.reason);
      store_.set_order(id, "FAILED", why, 1);
      store_.journal("cellctl", "FAILED", id, why);
      log_("order " + id + " failed: " + why);
      continue;
    }
    try {
      twins_[id] = std::make_unique<Process>("twin-" + id, twin_argv(cell_, executable_dir(), id, o.product, o.out, o.sequence, o.path,
                                                                      cell_.state_folder()));
      store_.journal("cellctl", "twin started", id, "attempt " + std::to_string(attempt));
      if (attempt > 1) log_("order " + id + ": twin started again (attempt " + std::to_string(attempt) + ")");
    } catch (const std::exception& e) {
      store_.set_order(id, "FAILED", std::string("its twin cannot be started: ") + e.what(), 1);
    }
  }
}

void OrderDesk::interrupt_all() {
  std::vector<Process*> all;
  for (auto& [id, twin] : twins_) all.push_back(twin.get());
  stop_all(all);
  twins_.clear();
}

}  // namespace cellctl
