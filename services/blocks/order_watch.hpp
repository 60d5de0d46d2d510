#pragma once
// Order status -> ENDED when an order is done, failed, or its twin is gone (its status'
// liveliness lease ran out); ACTIVE while it runs (an order id may be used again). Every
// resource frees what an ended order held through it; cell-sim removes the order's bodies.
//
// A cell that takes orders up again after their twin died (`resumable` says which) keeps a
// gone order SUSPENDED instead: what it booked stays, its queued work goes on, and a new
// twin of the order takes it up. It ends when `resumable` no longer holds (the order ended
// in the cell's state) or when no twin came back within `grace`; CHECK looks (call it now
// and then).
//
//   inputs: STATUS (order_id, ended), GONE (order_id), CHECK    outputs: ENDED, ACTIVE (order_id)

#include <chrono>
#include <functional>
#include <map>
#include <string>

#include "services/runtime/function_block.hpp"

namespace fb {

class OrderWatch : public FunctionBlock {
 public:
  using Resumable = std::function<bool(const std::string& order)>;
  explicit OrderWatch(Resumable resumable = {}, std::chrono::seconds grace = std::chrono::seconds(120))
      : FunctionBlock("order_watch"), resumable_(std::move(resumable)), grace_(grace) {
    declare_input("STATUS", {"order_id", "ended"});
    declare_input("GONE", {"order_id"});
    declare_input("CHECK");
    declare_output("ENDED", {"order_id"});
    declare_output("ACTIVE", {"order_id"});
  }
  const std::map<std::string, std::chrono::steady_clock::time_point>& suspended() const { return suspended_; }

  void receive(const Event& e) override {
    const auto now = std::chrono::steady_clock::now();
    if (e.name == "CHECK") {
      for (auto it = suspended_.begin(); it != suspended_.end();) {
        if (resumable_(it->first) && now - it->second < grace_) {
          ++it;
          continue;
        }
        emit("ENDED", {{"order_id", it->first}});
        it = suspended_.erase(it);
      }
      return;
    }
    const std::string order = get<std::string>(e.data, "order_id");
    if (e.name == "GONE" && resumable_ && resumable_(order)) {
      suspended_.emplace(order, now);
      return;
    }
    suspended_.erase(order);
    const bool ended = e.name == "GONE" || get<bool>(e.data, "ended");
    emit(ended ? "ENDED" : "ACTIVE", {{"order_id", order}});
  }

 private:
  Resumable resumable_;
  std::chrono::seconds grace_;
  std::map<std::string, std::chrono::steady_clock::time_point> suspended_;
};

}  // namespace fb
