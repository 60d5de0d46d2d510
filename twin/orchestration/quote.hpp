#pragma once
// A cell's answer to a request for a quote (docs/quotes.md): from the bids its resources
// made (nothing awarded) and the times virtual assembly measured, when the product would be
// done and what it would cost at the cell's rates.

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "twin/planning/assembly_planner.hpp"

namespace twin {

// What the resources offered, in s of sim time (the physical cell's time).
struct QuoteBids {
  std::string station, robot;
  double station_wait = 0;  // the station's bid: the orders in its queue, from now
  double robot_wait = 0;    // the robot's bid: the fetches it has taken on, from now
  std::vector<double> fetch;  // each step's fetch, in planned order (0: it fetches nothing)
  std::vector<double> arm;    // the arm's time for each step: from the dock, in, back
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

// The fetches and the arm as a two-stage flow: the robot starts once the station is the
// order's (and the robot is free), brings the parts one after another; the arm inserts each
// once it is delivered and the step before is done.
Quote estimate_quote(const QuoteBids& bids, const Rates& rates);
Quote infeasible_quote(const std::string& reason, const Rates& rates);

// quote.json (schema agile-cell/quote): the quote, the plan's size and every finding.
nlohmann::json quote_json(const std::string& order, const Quote& quote, std::size_t steps,
                          const std::vector<Finding>& findings);

}  // namespace twin
