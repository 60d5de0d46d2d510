#include "twin/orchestration/quote.hpp"

#include <algorithm>
#include <numeric>

namespace twin {
namespace {

double rate(const Rates& rates, const std::string& resource) {
  const auto it = rates.per_hour.find(resource);
  return it == rates.per_hour.end() ? 0 : it->second;
}

}  // namespace

Quote estimate_quote(const QuoteBids& bids, const Rates& rates) {
  Quote q;
  q.feasible = true;
  q.station = bids.station;
  q.robot = bids.robot;
  // From now: the station is the order's after its queue, the robot sets out once the station
  // is the order's and its own earlier fetches are done.
  const double start = std::max(0.0, bids.station_wait);
  double delivered = std::max(start, bids.robot_wait);
  double arm_done = start;
  for (std::size_t i = 0; i < bids.arm.size(); ++i) {
    if (i < bids.fetch.size()) delivered += bids.fetch[i];
    arm_done = std::max(arm_done, delivered) + bids.arm[i];
  }
  q.wait_s = start;
  q.makespan_s = arm_done;
  q.station_s = arm_done - start;
  q.robot_s = std::accumulate(bids.fetch.begin(), bids.fetch.end(), 0.0);
  q.setup_cost = rates.setup_cost;
  q.station_cost = q.station_s / 3600 * rate(rates, bids.station);
  q.robot_cost = q.robot_s / 3600 * rate(rates, bids.robot);
  q.total_cost = q.setup_cost + q.station_cost + q.robot_cost;
  q.currency = rates.currency;
  return q;
}

Quote infeasible_quote(const std::string& reason, const Rates& rates) {
  Quote q;
  q.reason = reason;
  q.currency = rates.currency;
  return q;
}

nlohmann::json quote_json(const std::string& order, const Quote& q, std::size_t steps,
                          const std::vector<Finding>& findings) {
  nlohmann::json found = nlohmann::json::array();
  for (const auto& f : findings) found.push_back({{"kind", f.kind}, {"message", f.message}, {"parts", f.parts}});
  nlohmann::json j = {{"schema", "agile-cell/quote"}, {"version", 1}, {"order", order}, {"feasible", q.feasible},
                      {"steps", steps}, {"findings", found}};
  if (!q.feasible) {
    j["reason"] = q.reason;
    return j;
  }
  j["station"] = q.station;
  j["robot"] = q.robot;
  j["time_s"] = {{"makespan", q.makespan_s}, {"wait", q.wait_s}, {"station", q.station_s}, {"robot", q.robot_s}};
  j["cost"] = {{"currency", q.currency}, {"setup", q.setup_cost}, {"station", q.station_cost},
               {"robot", q.robot_cost}, {"total", q.total_cost}};
  return j;
}

}  // namespace twin
