#pragma once
// The manager's side of the contract net (design.md 7), after Open-RMF's task dispatcher: a
// call goes out to every resource; bids and refusals come back; once every resource that has
// the operation has answered (or the bidding window closed) the best bid is awarded, chosen
// by a BidEvaluator; the resource confirms (possibly as a place in its queue) or refuses,
// and then the next best is awarded. A call that nobody bids on is called again until the
// wait runs out; then it is UNAVAILABLE, with every refusal's reason. The block knows no
// products: a call is an operation and its parameters.
//
// ASK is a call for quotes: the same bidding, and the best bid is reported (QUOTED) instead of
// awarded, so that an order can learn what the cell would offer without taking anything. A
// call for quotes that every resource with the operation refused is UNAVAILABLE after
// `quote_patience` (a resource discovered late may still bid), not after the whole `wait`.
// An UNAVAILABLE reason names each resource that was not heard: one that offers the operation
// and never answered, and one of the cell's roster of a kind that offers it whose capability
// never came (or went): the twin does not blame the stock it heard for what it cannot see.
//
//   inputs                                          outputs
//   CALL (call_id, operation, part_type, station,   CFP (the call, with order_id)
//         sources, count, duration)                 AWARD (call_id, resource_id, order_id, lease)
//   ASK (as CALL: a call for quotes)                QUOTED (call_id, resource_id, earliest_start, duration,
//                                                           bid_time)
//   CAPABILITY (resource_id, kind, operations):     AWARDED (call_id, resource_id, ahead,
//     who may answer                                         earliest_start, duration)
//   RESOURCE_GONE (resource_id)                     UNAVAILABLE (call_id, reason)
//   ROSTER (resources: "id<TAB>kind" lines): the
//     cell's resources, heard or not
//   PROPOSAL (call_id, resource_id, available, reason, earliest_start, duration, bid_time)
//   AWARD_REPLY (call_id, resource_id, confirmed, reason, ahead)
//   TICK: windows and waits (wall time)

#include <chrono>
#include <map>
#include <memory>
#include <set>
#include <string>

#include "services/runtime/function_block.hpp"

namespace fb {

struct Bid {
  std::string resource_id;
  double earliest_start = 0;  // sim s
  double duration = 0;        // s
  double bid_time = 0;        // the bidder's sim time when it bid
  std::string operation;      // the call's
};

// Which bid wins: the lowest cost. The interface is small so that a cell can weigh bids its
// own way (energy, wear, a preferred resource) without touching the negotiation.
class BidEvaluator {
 public:
  virtual ~BidEvaluator() = default;
  virtual double cost(const Bid& bid) const = 0;
};

// Open-RMF's default: the bid that finishes first.
class EarliestFinish : public BidEvaluator {
 public:
  double cost(const Bid& bid) const override { return bid.earliest_start + bid.duration; }
};

struct NegotiationSettings {
  std::chrono::milliseconds window{500};        // for bids, once the call is out
  std::chrono::milliseconds reply_timeout{2000};  // for a confirmation of an award
  std::chrono::milliseconds retry{1000};        // call again when nobody bid
  std::chrono::milliseconds wait{30000};        // then the call is UNAVAILABLE
  std::chrono::milliseconds quote_patience{3000};  // a call for quotes everyone refused
  double lease_s = 10;
};

class Negotiator : public FunctionBlock {
 public:
  Negotiator(std::string name, std::string order_id, NegotiationSettings settings,
             std::shared_ptr<const BidEvaluator> evaluator = std::make_shared<EarliestFinish>());

  void receive(const Event& event) override;
  std::size_t open_calls() const { return calls_.size(); }

 private:
  using Clock = std::chrono::steady_clock;
  struct Call {
    Data data;
    Clock::time_point started, called, awarded_at;
    std::map<std::string, Bid> bids;
    std::map<std::string, std::string> refusals;  // resource -> why
    std::string awarded;                          // waiting for its reply
    bool quote = false;                           // ASK: the best bid is reported, not awarded
    // Awarded before, and its reply did not come in time: a confirmation that still comes
    // is taken (the resource holds what it confirmed), while no other award is out.
    std::map<std::string, Bid> late;
  };
  void call(Call& c);
  // Awards the best bid, or reports it for a call for quotes (which ends the call: true).
  bool decide(const std::string& id);
  void unavailable(const std::string& id);
  void tick();
  bool all_answered(const Call& c) const;
  void refused(const std::string& id, const std::string& resource, const std::string& reason);

  std::string order_id_;
  NegotiationSettings settings_;
  std::shared_ptr<const BidEvaluator> evaluator_;
  std::map<std::string, std::set<std::string>> operations_;  // alive resource -> its operations
  std::map<std::string, std::string> kinds_;                 // heard resource -> its kind
  std::map<std::string, std::string> roster_;                // the cell's resource -> its kind
  std::set<std::string> gone_;                               // heard, then gone
  std::map<std::string, Call> calls_;
};

}  // namespace fb
