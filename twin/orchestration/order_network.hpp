#pragma once
// The twin's application: the OrderOrchestrator and the Negotiator (the manager's side of
// the contract net) on one resource, wired to each other. Where their other events come
// from and go to is the mapping's business: the twin process binds them to DDS topics, the
// tests to a stand-in cell.
//
//   into "orchestrator": START, TICK, CAPABILITY, RESOURCE_GONE, COMMAND_EVENT, SIM_REPLY
//   into "negotiator":   TICK, CAPABILITY, RESOURCE_GONE, PROPOSAL, AWARD_REPLY
//   out of "orchestrator": RELEASE, PREPARE, COMMAND, CANCEL, SIM, STATUS, FINDING, PLACED, QUOTE, FINISHED
//   out of "negotiator":   CFP, AWARD

#include <memory>

#include "services/blocks/negotiator.hpp"
#include "services/runtime/resource.hpp"
#include "twin/orchestration/order_orchestrator.hpp"

namespace twin {

// The earliest finish, where a station's time to host the order is the order's own model of
// its assembly there (OrderOrchestrator::hold_at: that station's arm, dock and table), not
// the one estimate every station was called with: a faster arm takes the order. Other bids
// finish when they say.
class ModelledFinish : public fb::BidEvaluator {
 public:
  explicit ModelledFinish(const OrderOrchestrator& orchestrator) : orchestrator_(orchestrator) {}
  double cost(const fb::Bid& bid) const override {
    const double hold = bid.operation == "host" ? orchestrator_.hold_at(bid.resource_id) : -1;
    return bid.earliest_start + (hold >= 0 ? hold : bid.duration);
  }

 private:
  const OrderOrchestrator& orchestrator_;
};

// `evaluator`: nullptr weighs bids by ModelledFinish.

inline OrderOrchestrator& add_order_network(fb::Resource& resource, const LoadedProduct& product, const Plan& plan,
                                            const OrderSettings& order, const fb::NegotiationSettings& negotiation,
                                            std::shared_ptr<const fb::BidEvaluator> evaluator = nullptr) {
  auto& orchestrator = resource.add(std::make_unique<OrderOrchestrator>("orchestrator", product, plan, order));
  if (!evaluator) evaluator = std::make_shared<ModelledFinish>(orchestrator);
  resource.add(std::make_unique<fb::Negotiator>("negotiator", order.order_id, negotiation, std::move(evaluator)));
  resource.connect("orchestrator", "CALL", "negotiator", "CALL");
  resource.connect("orchestrator", "ASK", "negotiator", "ASK");
  resource.connect("negotiator", "AWARDED", "orchestrator", "AWARDED");
  resource.connect("negotiator", "QUOTED", "orchestrator", "QUOTED");
  resource.connect("negotiator", "UNAVAILABLE", "orchestrator", "UNAVAILABLE");
  return orchestrator;
}

}  // namespace twin
