#pragma once
// The resource's side of the contract net (design.md 7), after Open-RMF's bidding: every call
// for an operation the resource offers gets an answer, a bid or a refusal with the reason. A bid
// says when the resource could start (from its own queue) and how long the work would take
// (from the device: its distances and speeds, or the caller's estimate of how long it holds
// an exclusive resource). It knows nothing about products: what it can do, and how long it
// takes, come from the service through `estimate`.
//
//  - An exclusive resource (a station, an arm) is held by one order at a time. An award
//    while it is held is confirmed as a place in its queue of waiting orders ("ahead": the
//    orders before it); when the holder releases it or ends (finished, failed, its twin
//    gone), the next in the queue holds it, and RESERVED says so.
//  - A shared resource (a mobile robot, a buffer) confirms every award and takes the work
//    into its queue: its next bid starts after the work it has taken.
//
//   inputs                                         outputs
//   CFP     (call_id, order_id, operation, ...)    PROPOSE  (call_id, available, reason, earliest_start, duration, bid_time)
//   AWARD   (call_id, resource_id, order_id)       REPLY    (call_id, order_id, confirmed, reason, ahead)
//   RELEASE (order_id, resource_id)                RESERVED (order_id): the holder changed, or the queue
//   ORDER_ENDED (order_id)                         AWARDED  (the call's data, duration): work taken on
//   IDLE: the device has no work left (a shared resource's queue estimate starts again from now)
//   SERVICE (out_of_service): the operator's word (the cell's roster); not "": why it is out of
//     service. Then every call is refused with that reason, and so is an award of a bid made
//     before; the orders that hold it or wait for it, and the work it took on, it still does.

#include <deque>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "services/runtime/basic_block.hpp"

namespace fb {

class Contractor : public BasicBlock {
 public:
  struct Estimate {
    bool available = false;
    std::string reason;     // why not, when not available
    double duration = 0;    // s of sim time
  };
  // The device's answer to a call (operation, part_type, station, sources, count, duration).
  using EstimateFn = std::function<Estimate(const Data& call)>;
  using Clock = std::function<double()>;  // sim time now

  // `offers`: the operations it bids for; calls for others go unanswered.
  Contractor(std::string name, std::string resource_id, std::set<std::string> offers, bool exclusive,
             EstimateFn estimate, Clock now);
  const std::set<std::string>& offers() const { return offers_; }

  const std::string& reserved_by() const { return holder_.order; }
  const std::string& out_of_service() const { return out_of_service_; }
  std::vector<std::string> waiting() const;
  // What the resource has taken on: the order that holds it and those waiting, in turn
  // (exclusive), or the orders whose work it took (shared), with the awards of each. A
  // process that follows one that ended takes them up again (restore), so that a station
  // restarted with a half-built product on its table is still its order's.
  struct Booking {
    std::string order;
    std::set<std::string> calls;
    double duration = 0;
    bool holds = false;  // exclusive: the holder
  };
  std::vector<Booking> bookings() const;
  void restore(const std::vector<Booking>& bookings);
  // Called with the bookings each time they change (an award taken, an order ended).
  void persist_with(std::function<void(const std::vector<Booking>&)> persist) { persist_ = std::move(persist); }

  // Authorization of a command: "" when `award` is a call this resource confirmed for
  // `order` and the order holds the resource now (exclusive) or has work taken on by it
  // (shared); otherwise why not ("arm-1 is reserved by ok1").
  std::string refusal(const std::string& order, const std::string& award) const;

 private:
  struct Hold {
    std::string order;
    double until = 0;  // expected end, sim s
    double duration = 0;
    std::set<std::string> calls;  // the awards it holds this resource by
  };
  double earliest_start(const std::string& order, double now) const;
  std::string out_of_service_reason() const;
  void award(const Data& award);
  long place_of(const std::string& order, const std::string& call) const;
  void end(const std::string& order);
  void propose(const Data& call);
  void reply(const std::string& call_id, const std::string& order, bool confirmed, const std::string& reason, long ahead);

  std::string resource_id_;
  std::set<std::string> offers_;
  bool exclusive_;
  EstimateFn estimate_;
  Clock now_;
  Hold holder_;                                // exclusive: who holds it
  std::deque<Hold> waiting_;                   // exclusive: who waits, in turn
  std::map<std::string, Data> bids_;           // call id -> the call offered for, with the bid's duration
  std::map<std::string, std::set<std::string>> work_;  // shared: order -> awards taken on
  double busy_until_ = 0;                      // shared: the end of the work taken on
  std::string out_of_service_;                 // why it takes no new work; "" in service
  std::function<void(const std::vector<Booking>&)> persist_;
  void persist() const {
    if (persist_) persist_(bookings());
  }
};

}  // namespace fb
