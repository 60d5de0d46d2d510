#include "services/blocks/contractor.hpp"

#include <algorithm>
#include <cmath>

namespace fb {

Contractor::Contractor(std::string name, std::string resource_id, std::set<std::string> offers, bool exclusive,
                       EstimateFn estimate, Clock now)
    : BasicBlock(std::move(name), "READY"), resource_id_(std::move(resource_id)), offers_(std::move(offers)),
      exclusive_(exclusive),
      estimate_(std::move(estimate)), now_(std::move(now)) {
  declare_input("CFP", {"call_id", "order_id", "operation", "part_type", "station", "sources", "count", "duration"});
  declare_input("AWARD", {"call_id", "resource_id", "order_id"});
  declare_input("RELEASE", {"order_id", "resource_id"});
  declare_input("ORDER_ENDED", {"order_id"});
  declare_input("IDLE");
  declare_input("SERVICE", {"out_of_service"});
  declare_output("PROPOSE", {"call_id", "available", "reason", "earliest_start", "duration", "bid_time"});
  declare_output("REPLY", {"call_id", "confirmed", "reason", "ahead"});
  declare_output("RESERVED", {"order_id"});
  declare_output("AWARDED", {"call_id", "order_id", "duration"});

  const auto for_me = [this](const Data& d) { return get<std::string>(d, "resource_id") == resource_id_; };
  transition("READY", "CFP", "READY", [this](const Data& d) { propose(d); },
             [this](const Data& d) { return offers_.count(get<std::string>(d, "operation")) > 0; });
  transition("READY", "AWARD", "READY", [this](const Data& d) { award(d); }, for_me);
  transition("READY", "RELEASE", "READY", [this](const Data& d) { end(get<std::string>(d, "order_id")); }, for_me);
  transition("READY", "ORDER_ENDED", "READY", [this](const Data& d) { end(get<std::string>(d, "order_id")); });
  transition("READY", "IDLE", "READY", [this](const Data&) { busy_until_ = now_(); });
  transition("READY", "SERVICE", "READY", [this](const Data& d) { out_of_service_ = get<std::string>(d, "out_of_service"); });
}

std::vector<std::string> Contractor::waiting() const {
  std::vector<std::string> out;
  for (const Hold& h : waiting_) out.push_back(h.order);
  return out;
}

std::vector<Contractor::Booking> Contractor::bookings() const {
  std::vector<Booking> out;
  if (!holder_.order.empty()) out.push_back({holder_.order, holder_.calls, holder_.duration, true});
  for (const Hold& h : waiting_) out.push_back({h.order, h.calls, h.duration, false});
  for (const auto& [order, calls] : work_) out.push_back({order, calls, 0, false});
  return out;
}

void Contractor::restore(const std::vector<Booking>& bookings) {
  const double now = now_();
  for (const Booking& b : bookings) {
    if (!exclusive_) {
      work_[b.order].insert(b.calls.begin(), b.calls.end());
    } else if (b.holds && holder_.order.empty()) {
      holder_ = {b.order, now + b.duration, b.duration, b.calls};
    } else {
      waiting_.push_back({b.order, 0, b.duration, b.calls});
    }
  }
  if (exclusive_ && holder_.order.empty() && !waiting_.empty()) {  // its holder ended meanwhile
    holder_ = waiting_.front();
    holder_.until = now + holder_.duration;
    waiting_.pop_front();
  }
}

std::string Contractor::refusal(const std::string& order, const std::string& award) const {
  if (award.empty()) return "the command names no award of " + resource_id_;
  const std::string of_order = " of order " + (order.empty() ? std::string("''") : order);
  if (!exclusive_) {
    const auto it = work_.find(order);
    return it != work_.end() && it->second.count(award) ? "" : resource_id_ + " has no award " + award + of_order;
  }
  if (holder_.order.empty()) return resource_id_ + " is not reserved" + of_order;
  if (holder_.order != order) return resource_id_ + " is reserved by " + holder_.order;
  return holder_.calls.count(award) ? "" : resource_id_ + " has no award " + award + of_order;
}

std::string Contractor::out_of_service_reason() const { return resource_id_ + " is out of service: " + out_of_service_; }

// Exclusive: after the holder's expected end and the expected holds of those waiting.
// Shared: after the work taken on.
double Contractor::earliest_start(const std::string& order, double now) const {
  if (!exclusive_) return std::max(now, busy_until_);
  if (holder_.order.empty() || holder_.order == order) return now;
  double start = std::max(now, holder_.until);
  for (const Hold& h : waiting_) {
    if (h.order == order) break;
    start += h.duration;
  }
  return start;
}

void Contractor::propose(const Data& call) {
  // A call from the network is checked before the device is asked.
  const double hold = get_or<double>(call, "duration", 0);
  const std::int64_t count = get_or<std::int64_t>(call, "count", 0);
  const Estimate e = !out_of_service_.empty()          ? Estimate{false, out_of_service_reason(), 0}
                     : !std::isfinite(hold) || hold < 0 ? Estimate{false, "the call's duration is not a number >= 0", 0}
                     : count < 0                        ? Estimate{false, "the call's count is negative", 0}
                                                        : estimate_(call);
  const std::string& id = get<std::string>(call, "call_id");
  if (e.available) {
    Data offered = call;
    offered["duration"] = e.duration;
    bids_[id] = std::move(offered);
  }
  const double now = now_();
  emit("PROPOSE", {{"call_id", id}, {"available", e.available}, {"reason", e.reason},
                   {"earliest_start", e.available ? earliest_start(get<std::string>(call, "order_id"), now) : 0.0},
                   {"duration", e.duration}, {"bid_time", now}});
}

void Contractor::reply(const std::string& call_id, const std::string& order, bool confirmed, const std::string& reason,
                       long ahead) {
  emit("REPLY", {{"call_id", call_id}, {"order_id", order}, {"confirmed", confirmed}, {"reason", reason},
                 {"ahead", std::int64_t(ahead)}});
}

void Contractor::award(const Data& d) {
  const std::string& call = get<std::string>(d, "call_id");
  const std::string& order = get<std::string>(d, "order_id");
  // A call it took already, awarded again (its confirmation came too late for the order, which
  // called again): confirmed again, not taken twice (a buffer would keep its parts twice).
  if (const long place = place_of(order, call); place >= 0) {
    bids_.erase(call);
    return reply(call, order, true, "", place);
  }
  const auto bid = bids_.find(call);
  if (bid == bids_.end()) return reply(call, order, false, resource_id_ + " made no offer for call " + call, 0);
  if (!out_of_service_.empty()) {
    bids_.erase(bid);
    return reply(call, order, false, out_of_service_reason(), 0);
  }
  if (get<std::string>(bid->second, "order_id") != order) {
    return reply(call, order, false, "call " + call + " was made by order " + get<std::string>(bid->second, "order_id"), 0);
  }
  Data awarded = std::move(bid->second);
  bids_.erase(bid);
  awarded["order_id"] = order;
  const double duration = get<double>(awarded, "duration");
  const double now = now_();
  if (!exclusive_) {
    work_[order].insert(call);
    persist();  // before the confirmation: what was confirmed survives a restart
    busy_until_ = std::max(now, busy_until_) + duration;
    reply(call, order, true, "", 0);
    return emit("AWARDED", std::move(awarded));
  }
  if (holder_.order.empty() || holder_.order == order) {
    std::set<std::string> calls = holder_.order == order ? holder_.calls : std::set<std::string>{};
    calls.insert(call);
    holder_ = {order, now + duration, duration, std::move(calls)};
    persist();
    reply(call, order, true, "", 0);
  } else {
    auto it = std::find_if(waiting_.begin(), waiting_.end(), [&](const Hold& h) { return h.order == order; });
    if (it == waiting_.end()) it = waiting_.insert(waiting_.end(), {order, 0, duration, {}});
    it->calls.insert(call);
    persist();
    reply(call, order, true, "", 1 + (it - waiting_.begin()));
  }
  emit("RESERVED", {{"order_id", holder_.order}});
  emit("AWARDED", std::move(awarded));
}

// Where the order's award of `call` stands: 0 held (or taken on, shared), n the n-th in the
// queue; -1 not taken.
long Contractor::place_of(const std::string& order, const std::string& call) const {
  if (!exclusive_) {
    const auto it = work_.find(order);
    return it != work_.end() && it->second.count(call) ? 0 : -1;
  }
  if (holder_.order == order && holder_.calls.count(call)) return 0;
  for (std::size_t i = 0; i < waiting_.size(); ++i) {
    if (waiting_[i].order == order && waiting_[i].calls.count(call)) return static_cast<long>(i) + 1;
  }
  return -1;
}

// The order is done with this resource: released, or ended.
void Contractor::end(const std::string& order) {
  for (auto it = bids_.begin(); it != bids_.end();) {
    it = get<std::string>(it->second, "order_id") == order ? bids_.erase(it) : std::next(it);
  }
  if (!exclusive_) {
    if (work_.erase(order) > 0) persist();
    return;
  }
  const auto it = std::find_if(waiting_.begin(), waiting_.end(), [&](const Hold& h) { return h.order == order; });
  if (it != waiting_.end()) {
    waiting_.erase(it);
  } else if (holder_.order == order && !order.empty()) {
    holder_ = {};
    if (!waiting_.empty()) {
      holder_ = waiting_.front();
      holder_.until = now_() + holder_.duration;
      waiting_.pop_front();
    }
  } else {
    return;
  }
  persist();
  emit("RESERVED", {{"order_id", holder_.order}});
}

}  // namespace fb
