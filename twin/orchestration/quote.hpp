#pragma once
// A cell's answer to a request for a quote (docs/quotes.md): when the product would be done,
// by the order's physical script run against the models of the resources that bid (nothing
// awarded), and what it would cost at the cell's rates.

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "twin/planning/assembly_planner.hpp"

namespace twin {

// The order's physical assembly as the cell's model ran it (execution_model.hpp), in s of
// sim time (the physical cell's time) from the moment of the quote.
struct QuoteTimes {
  std::string station, robot;
  double wait = 0;      // until the station is the order's (its queue)
  double makespan = 0;  // until the last step is done
  double robot_s = 0;   // the robot drives for the order
};

struct Rates {
  double setup_cost = 0;                       // per order
  std::map<std::string, double> per_hour;      // resource id -> cost per hour of use; absent: 0
  std::string currency = "EUR";
};

struct Quote {
  bool feasible = false;
  std::string reason;  // why not
  std::string station, robot;
  double wait_s = 0;      // until the station is free
  double makespan_s = 0;  // from now until the last part is in
  double station_s = 0;   // the order holds the station (and its arm)
  double robot_s = 0;     // the robot drives for the order
  double setup_cost = 0, station_cost = 0, robot_cost = 0, total_cost = 0;
  std::string currency;
};

// The times, and their cost at the cell's rates: the order holds the station (with its arm)
// from `wait` to `makespan`, the robot while it drives.
Quote price_quote(const QuoteTimes& times, const Rates& rates);
Quote infeasible_quote(const std::string& reason, const Rates& rates);

// quote.json (schema agile-cell/quote): the quote, the plan's size and every finding.
nlohmann::json quote_json(const std::string& order, const Quote& quote, std::size_t steps,
                          const std::vector<Finding>& findings);

}  // namespace twin
