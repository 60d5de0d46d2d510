#pragma once
// The resource's side of the contract net (design.md 7): it answers calls for proposals it
// can serve, and confirms or refuses awards. An exclusive resource (station, arm, mobile
// robot) is reserved by the order it confirmed until that order releases it or ends (its
// twin finished, failed or disappeared); a shared one (a buffer) confirms every award.
// It knows nothing about products: what it can serve is a predicate on operation and part
// type, given by the service.
//
//   inputs                                         outputs
//   CFP     (call_id, order_id, operation,         PROPOSE  (call_id, earliest_start, duration)
//            part_type)                            REPLY    (call_id, confirmed, reason)
//   AWARD   (call_id, resource_id, order_id)       RESERVED (order_id): "" when free again
//   RELEASE (order_id, resource_id)
//   ORDER_ENDED (order_id)

#include <functional>

#include "services/runtime/basic_block.hpp"

namespace fb {

class Contractor : public BasicBlock {
 public:
  using CanServe = std::function<bool(const std::string& operation, const std::string& part_type)>;
  // `duration`: what the resource proposes for one operation, s of sim time.
  Contractor(std::string name, std::string resource_id, bool exclusive, CanServe can_serve, double duration = 0);

  const std::string& reserved_by() const { return order_; }

 private:
  std::string resource_id_;
  CanServe can_serve_;
  double duration_;
  std::string order_;
};

}  // namespace fb
