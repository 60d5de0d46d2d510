#include "twin/orchestration/quote.hpp"

#include <algorithm>

namespace twin {
namespace {

double rate(const Rates& rates, const std::string& resource) {
  const auto it = rates.per_hour.find(resource);
  return it == rates.per_hour.end() ? 0 : it->second;
}

}  // namespace

Quote price_quote(const QuoteTimes& times, const Rates& rates) {
  Quote q;
  q.feasible = true;
  q.station = times.station;
  q.robot = times.robot;
  q.wait_s = times.wait;
  q.makespan_s = times.makespan;
  q.station_s = times.makespan - times.wait;
  q.robot_s = times.robot_s;
  q.setup_cost = rates.setup_cost;
  q.station_cost = q.station_s / 3600 * rate(rates, times.station);
  q.robot_cost = q.robot_s / 3600 * rate(rates, times.robot);
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
