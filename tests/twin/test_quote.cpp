// A quote's cost from the modelled times, and quote.json (twin/orchestration/quote).

#include <catch2/catch.hpp>

#include "twin/orchestration/quote.hpp"

TEST_CASE("quote: the order holds the station from its wait to its makespan and the robot while it drives, each at its rate",
          "[twin][quote]") {
  const twin::Rates rates{50, {{"station-2", 360}, {"mobile-robot-1", 36}, {"station-1", 1e6}}, "CHF"};
  const twin::Quote q = twin::price_quote({"station-2", "mobile-robot-1", 30, 55, 12}, rates);
  CHECK(q.feasible);
  CHECK(q.wait_s == Approx(30));
  CHECK(q.makespan_s == Approx(55));
  CHECK(q.station_s == Approx(25));
  CHECK(q.robot_s == Approx(12));
  CHECK(q.station_cost == Approx(25.0 / 3600 * 360));
  CHECK(q.robot_cost == Approx(12.0 / 3600 * 36));
  CHECK(q.total_cost == Approx(50 + 2.5 + 0.12));
  CHECK(q.currency == "CHF");
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
  const auto yes = twin::quote_json("o1", twin::price_quote({"station-1", "mobile-robot-1", 0, 3, 1}, rates), 1, findings);
  CHECK(yes["feasible"] == true);
  CHECK(yes["time_s"]["makespan"] == Approx(3));
  CHECK(yes["cost"]["total"] == Approx(20));
  CHECK(yes["cost"]["currency"] == "EUR");
  REQUIRE(yes["findings"].size() == 1);
  CHECK(yes["findings"][0]["parts"][1] == "back");
}
