#include "services/blocks/contractor.hpp"

namespace fb {

Contractor::Contractor(std::string name, std::string resource_id, bool exclusive, CanServe can_serve, double duration)
    : BasicBlock(std::move(name), "FREE"), resource_id_(std::move(resource_id)), can_serve_(std::move(can_serve)),
      duration_(duration) {
  declare_input("CFP", {"call_id", "order_id", "operation", "part_type"});
  declare_input("AWARD", {"call_id", "resource_id", "order_id"});
  declare_input("RELEASE", {"order_id", "resource_id"});
  declare_input("ORDER_ENDED", {"order_id"});
  declare_output("PROPOSE", {"call_id", "earliest_start", "duration"});
  declare_output("REPLY", {"call_id", "confirmed", "reason"});
  declare_output("RESERVED", {"order_id"});

  const auto servable = [this](const Data& d) {
    return can_serve_(get<std::string>(d, "operation"), get<std::string>(d, "part_type"));
  };
  const auto for_me = [this](const Data& d) { return get<std::string>(d, "resource_id") == resource_id_; };
  const auto of_holder = [this](const Data& d) { return get<std::string>(d, "order_id") == order_; };
  const auto propose = [this](const Data& d) {
    emit("PROPOSE", {{"call_id", get<std::string>(d, "call_id")}, {"earliest_start", 0.0}, {"duration", duration_}});
  };
  const auto reply = [this](const Data& d, bool confirmed, const std::string& reason) {
    emit("REPLY", {{"call_id", get<std::string>(d, "call_id")}, {"confirmed", confirmed}, {"reason", reason}});
  };

  transition("FREE", "CFP", "FREE", propose, servable);
  if (!exclusive) {
    transition("FREE", "AWARD", "FREE", [reply](const Data& d) { reply(d, true, ""); }, for_me);
    return;
  }
  transition("FREE", "AWARD", "RESERVED", [this, reply](const Data& d) {
    order_ = get<std::string>(d, "order_id");
    reply(d, true, "");
    emit("RESERVED", {{"order_id", order_}});
  }, for_me);
  // Reserved: the holder may call again (another operation of its order); others wait.
  transition("RESERVED", "CFP", "RESERVED", propose,
             [servable, of_holder](const Data& d) { return servable(d) && of_holder(d); });
  transition("RESERVED", "AWARD", "RESERVED", [reply](const Data& d) { reply(d, true, ""); },
             [for_me, of_holder](const Data& d) { return for_me(d) && of_holder(d); });
  transition("RESERVED", "AWARD", "RESERVED", [this, reply](const Data& d) {
    reply(d, false, resource_id_ + " is reserved by order " + order_);
  }, for_me);
  const auto free = [this](const Data&) {
    order_.clear();
    emit("RESERVED", {{"order_id", std::string()}});
  };
  transition("RESERVED", "RELEASE", "FREE", free, [for_me, of_holder](const Data& d) { return for_me(d) && of_holder(d); });
  transition("RESERVED", "ORDER_ENDED", "FREE", free, of_holder);
}

}  // namespace fb
