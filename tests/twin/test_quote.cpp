// A quote's time and cost from the bids and the measured times (twin/orchestration/quote).

#include <catch2/catch.hpp>

#include "twin/orchestration/quote.hpp"

TEST_CASE("quote: the fetches and the arm as a two-stage flow, after the station's queue", "[twin][quote]") {
  twin::QuoteBids bids{"station-2", "mobile-robot-1", 30, 0, {4, 4, 4}, {10, 1, 10}};
  twin::Rates rates{50, {{"station-2", 360}, {"mobile-robot-1", 36}, {"station-1", 1e6}}, "CHF"};
  const twin::Quote q = twin::estimate_quote(bids, rates);
  CHECK(q.feasible);
  CHECK(q.wait_s == Approx(30));  // the station is free in 30 s
  // From 30: parts delivered at 34, 38, 42; the arm: 34-44, 44-45, 45-55.
  CHECK(q.makespan_s == Approx(55));
  CHECK(q.station_s == Approx(25));
  CHECK(q.robot_s == Approx(12));
  CHECK(q.station_cost == Approx(25.0 / 3600 * 360));
  CHECK(q.robot_cost == Approx(12.0 / 3600 * 36));
  CHECK(q.total_cost == Approx(50 + 2.5 + 0.12));
  CHECK(q.currency == "CHF");

  // A robot busy past the station's start holds the arm up.
  bids.robot_wait = 50;
  bids.station_wait = 0;
  const twin::Quote later = twin::estimate_quote(bids, rates);
  CHECK(later.wait_s == 0);
  CHECK(later.makespan_s == Approx(75));  // delivered 54, 58, 62; arm 54-64, 64-65, 65-75
  CHECK(later.station_s == Approx(75));
}

TEST_CASE("quote: quote.json says feasible or why not, the time and the cost, and every finding", "[twin][quote]") {
  const std::vector<twin::Finding> findings{{"margin", "step 2 (shaft): 0.50 mm", {"shaft", "back"}}};
  twin::Rates rates;
  rates.setup_cost = 20;
  const auto no = twin::quote_json("o1", twin::infeasible_quote("nobody offered give Shaft", rates), 9, findings);
  CHECK(no["schema"] == "agile-cell/quote");
  CHECK(no["feasible"] == false);
  CHECK(no["reason"] == "nobody offered give Shaft");
  CHECK_FALSE(no.contains("cost"));
  const auto yes = twin::quote_json("o1", twin::estimate_quote({"station-1", "mobile-robot-1", 0, 0, {1}, {2}}, rates), 1, findings);
  CHECK(yes["feasible"] == true);
  CHECK(yes["time_s"]["makespan"] == Approx(3));
  CHECK(yes["cost"]["total"] == Approx(20));
  CHECK(yes["cost"]["currency"] == "EUR");
  REQUIRE(yes["findings"].size() == 1);
  CHECK(yes["findings"][0]["parts"][1] == "back");
}
