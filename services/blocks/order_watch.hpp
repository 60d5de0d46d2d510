#pragma once
// Order status -> ENDED when an order is done, failed, or its twin is gone (its status'
// liveliness lease ran out); ACTIVE while it runs (an order id may be used again). Every
// resource frees what an ended order held through it; cell-sim removes the order's bodies.
//
//   inputs: STATUS (order_id, ended), GONE (order_id)    outputs: ENDED, ACTIVE (order_id)

#include "services/runtime/function_block.hpp"

namespace fb {

class OrderWatch : public FunctionBlock {
 public:
  OrderWatch() : FunctionBlock("order_watch") {
    declare_input("STATUS", {"order_id", "ended"});
    declare_input("GONE", {"order_id"});
    declare_output("ENDED", {"order_id"});
    declare_output("ACTIVE", {"order_id"});
  }
  void receive(const Event& e) override {
    const bool ended = e.name == "GONE" || get<bool>(e.data, "ended");
    emit(ended ? "ENDED" : "ACTIVE", {{"order_id", e.data.at("order_id")}});
  }
};

}  // namespace fb
