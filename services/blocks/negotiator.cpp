#include "services/blocks/negotiator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace fb {

Negotiator::Negotiator(std::string name, std::string order_id, NegotiationSettings settings,
                       std::shared_ptr<const BidEvaluator> evaluator)
    : FunctionBlock(std::move(name)), order_id_(std::move(order_id)), settings_(settings),
      evaluator_(std::move(evaluator)) {
  declare_input("CALL", {"call_id", "operation", "part_type", "station", "sources", "count", "duration"});
  declare_input("ASK", {"call_id", "operation", "part_type", "station", "sources", "count", "duration"});
  declare_input("CAPABILITY", {"resource_id", "kind", "operations"});
  declare_input("ROSTER", {"resources"});
  declare_input("RESOURCE_GONE", {"resource_id"});
  declare_input("PROPOSAL", {"call_id", "resource_id", "available", "reason", "earliest_start", "duration", "bid_time"});
  declare_input("AWARD_REPLY", {"call_id", "resource_id", "confirmed", "reason", "ahead"});
  declare_input("TICK");
  declare_output("CFP", {"call_id", "order_id", "operation", "part_type", "station", "sources", "count", "duration"});
  declare_output("AWARD", {"call_id", "resource_id", "order_id", "lease"});
  declare_output("AWARDED", {"call_id", "resource_id", "ahead", "earliest_start", "duration"});
  declare_output("UNAVAILABLE", {"call_id", "reason"});
  declare_output("QUOTED", {"call_id", "resource_id", "earliest_start", "duration", "bid_time"});
}

void Negotiator::receive(const Event& e) {
  if (e.name == "TICK") return tick();
  if (e.name == "CAPABILITY") {
    const auto ops = split_names(get<std::string>(e.data, "operations"));
    const std::string& resource = get<std::string>(e.data, "resource_id");
    operations_[resource] = {ops.begin(), ops.end()};
    kinds_[resource] = get_or<std::string>(e.data, "kind", "");
    gone_.erase(resource);
    return;
  }
  if (e.name == "ROSTER") {
    roster_.clear();
    std::istringstream lines(get<std::string>(e.data, "resources"));
    for (std::string line; std::getline(lines, line);) {
      const auto tab = line.find('\t');
      if (tab != std::string::npos && tab > 0) roster_[line.substr(0, tab)] = line.substr(tab + 1);
    }
    return;
  }
  if (e.name == "RESOURCE_GONE") {
    const std::string& resource = get<std::string>(e.data, "resource_id");
    if (operations_.erase(resource)) gone_.insert(resource);
    for (auto& [id, c] : calls_) {
      c.bids.erase(resource);
      c.late.erase(resource);
      if (c.awarded == resource) refused(id, resource, resource + " disappeared");
    }
    return;
  }
  if (e.name == "CALL" || e.name == "ASK") {
    Call& c = calls_[get<std::string>(e.data, "call_id")];
    c = Call{e.data, Clock::now(), {}, {}, {}, {}, {}, e.name == "ASK", {}};
    c.data["order_id"] = order_id_;
    return call(c);
  }
  const auto it = calls_.find(get<std::string>(e.data, "call_id"));
  if (it == calls_.end()) return;  // an answer to a call that is settled
  Call& c = it->second;
  const std::string& resource = get<std::string>(e.data, "resource_id");
  if (e.name == "PROPOSAL") {
    const double start = get<double>(e.data, "earliest_start"), duration = get<double>(e.data, "duration");
    const double bid_time = get_or<double>(e.data, "bid_time", start);
    if (get<bool>(e.data, "available") &&
        (!std::isfinite(start) || !std::isfinite(duration) || duration < 0 || !std::isfinite(bid_time))) {
      c.refusals[resource] = "its bid was not a finite start, bid time and duration >= 0";
    } else if (get<bool>(e.data, "available")) {
      c.bids[resource] = {resource, start, duration, bid_time, get<std::string>(c.data, "operation")};
      c.refusals.erase(resource);
    } else {
      c.refusals[resource] = get<std::string>(e.data, "reason");
    }
    if (!c.awarded.empty() || !all_answered(c)) return;
    const std::string id = it->first;
    if (decide(id)) calls_.erase(id);
  } else if (e.name == "AWARD_REPLY" && (resource == c.awarded || (c.awarded.empty() && c.late.count(resource)))) {
    const bool late = resource != c.awarded;
    if (!get<bool>(e.data, "confirmed")) {
      if (late) return;  // refused what was given up on already
      return refused(it->first, resource, get<std::string>(e.data, "reason"));
    }
    const Bid bid = late ? c.late.at(resource) : c.bids[resource];
    const std::string id = it->first;
    calls_.erase(it);
    emit("AWARDED", {{"call_id", id}, {"resource_id", resource}, {"ahead", get<std::int64_t>(e.data, "ahead")},
                     {"earliest_start", bid.earliest_start}, {"duration", bid.duration}});
  }
}

void Negotiator::call(Call& c) {
  c.called = Clock::now();
  emit("CFP", c.data);
}

// Every resource heard that offers the operation answered, and the cell's roster has none of
// a kind that offers it which this twin has not heard yet (a cell still coming up: a robot
// whose capability is on its way may bid better; the bidding window waits for it).
bool Negotiator::all_answered(const Call& c) const {
  const std::string& op = get<std::string>(c.data, "operation");
  bool any = false;
  std::set<std::string> kinds;
  for (const auto& [resource, ops] : operations_) {
    if (!ops.count(op)) continue;
    any = true;
    if (const auto kind = kinds_.find(resource); kind != kinds_.end()) kinds.insert(kind->second);
    if (!c.bids.count(resource) && !c.refusals.count(resource)) return false;
  }
  for (const auto& [resource, kind] : roster_) {
    if (kinds.count(kind) && !operations_.count(resource) && !gone_.count(resource)) return false;
  }
  return any;
}

void Negotiator::refused(const std::string& id, const std::string& resource, const std::string& reason) {
  Call& c = calls_.at(id);
  c.bids.erase(resource);
  c.refusals[resource] = reason;
  c.awarded.clear();
  decide(id);  // an award's refusal: never a call for quotes
}

// The best bid is awarded (or quoted); with none, the call waits for the next one or runs out.
bool Negotiator::decide(const std::string& id) {
  Call& c = calls_.at(id);
  const Bid* best = nullptr;
  double best_cost = std::numeric_limits<double>::infinity();
  for (const auto& [resource, bid] : c.bids) {
    const double cost = evaluator_->cost(bid);
    if (cost < best_cost) best = &bid, best_cost = cost;
  }
  if (!best) return false;
  if (c.quote) {
    emit("QUOTED", {{"call_id", id}, {"resource_id", best->resource_id}, {"earliest_start", best->earliest_start},
                    {"duration", best->duration}, {"bid_time", best->bid_time}});
    return true;
  }
  c.awarded = best->resource_id;
  c.awarded_at = Clock::now();
  emit("AWARD", {{"call_id", id}, {"resource_id", c.awarded}, {"order_id", order_id_}, {"lease", settings_.lease_s}});
  return false;
}

void Negotiator::tick() {
  const auto now = Clock::now();
  std::vector<std::string> unavailable, quoted;
  for (auto& [id, c] : calls_) {
    if (!c.awarded.empty()) {
      if (now - c.awarded_at > settings_.reply_timeout) {
        if (c.bids.count(c.awarded)) c.late[c.awarded] = c.bids.at(c.awarded);
        refused(id, c.awarded, c.awarded + " did not confirm within " +
                                   std::to_string(settings_.reply_timeout.count()) + " ms");
      }
      continue;
    }
    if (!c.bids.empty() && now - c.called >= settings_.window) {
      if (decide(id)) quoted.push_back(id);
    } else if (c.bids.empty() && (now - c.started >= settings_.wait ||
                                  (c.quote && now - c.started >= settings_.quote_patience && all_answered(c)))) {
      unavailable.push_back(id);
    } else if (c.bids.empty() && now - c.called >= settings_.retry) {
      call(c);
    }
  }
  for (const auto& id : quoted) calls_.erase(id);
  for (const auto& id : unavailable) this->unavailable(id);
}

void Negotiator::unavailable(const std::string& id) {
  const Call& c = calls_.at(id);
  std::string reason = "nobody offered " + get<std::string>(c.data, "operation");
  const std::string type = get_or<std::string>(c.data, "part_type", "");
  if (!type.empty()) reason += " " + type;
  if (!c.quote || c.refusals.empty()) reason += " within " + std::to_string(settings_.wait.count() / 1000) + " s";
  std::string why;
  for (const auto& [resource, r] : c.refusals) why += (why.empty() ? "" : "; ") + resource + ": " + r;
  // A live resource that offers the operation and said nothing at all: its answers do not
  // reach this process (a DDS match lost under load), which the operator should know.
  const std::string& operation = get<std::string>(c.data, "operation");
  for (const auto& [resource, ops] : operations_) {
    if (ops.count(operation) && !c.refusals.count(resource)) {
      why += (why.empty() ? "" : "; ") + resource + " offers " + operation + " but never answered";
    }
  }
  // The cell's resources this twin does not hear, of a kind that offers the operation (any
  // kind, when it hears none that does): their capabilities never came, or went.
  std::set<std::string> kinds;
  for (const auto& [resource, ops] : operations_) {
    if (ops.count(operation)) kinds.insert(kinds_[resource]);
  }
  for (const auto& [resource, kind] : roster_) {
    if (operations_.count(resource) || !(kinds.empty() || kinds.count(kind))) continue;
    why += (why.empty() ? "" : "; ") + resource + " (" + kind + ") of the cell " +
           (gone_.count(resource) ? "has gone (its liveliness lease ran out)" : "has not been heard by this twin");
  }
  reason += why.empty() ? " (no resource with that operation answered)" : " (" + why + ")";
  calls_.erase(id);
  emit("UNAVAILABLE", {{"call_id", id}, {"reason", reason}});
}

}  // namespace fb
