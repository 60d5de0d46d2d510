// The chaos test, short (the full one is bench_chaos): orders on a cell with two stations
// and two robots while a killer SIGKILLs its processes, cellctl up once among them.

#include <algorithm>

#include <catch2/catch.hpp>

#include "tests/support/chaos.hpp"
#include "tests/support/domains.hpp"

namespace domains = test::domains;

TEST_CASE("chaos: kills of any process lose no part, leave no hold and no process, and every order ends with a reason",
          "[process][cell][state][chaos]") {
  test::ChaosOptions o;
  o.dir = test::scratch("chaos");
  o.cell = std::string(DEPLOY_CELLS) + "/two-stations.yaml";
  o.domain = domains::kChaos;
  o.orders = 4;
  o.kills = 6;
  o.first_victims = {"twin", "cell-sim"};  // besides the random picks and cellctl up
  o.order_timeout = std::chrono::seconds(150);
  const test::ChaosResult r = test::run_chaos(o);

  std::string kills, failures;
  for (const auto& k : r.kills) kills += k + "\n";
  for (const auto& f : r.failures) failures += f + "\n";
  INFO("kills:\n" << kills << "failures:\n" << failures);
  CHECK(r.kills.size() == 6);
  const auto killed = [&](const std::string& what) {
    return std::any_of(r.kills.begin(), r.kills.end(), [&](const std::string& k) { return k.find(what) != std::string::npos; });
  };
  CHECK(killed(" order-"));  // a twin with its order
  CHECK(killed(" cell-sim "));
  CHECK(killed(" cellctl up "));
  CHECK(r.unfinished == 0);
  CHECK(r.assembled + r.failed == 4);
  for (const auto& f : r.failures) CHECK(f.size() > std::string("order-1: ").size() + 10);  // a stated reason
  CHECK(r.conservation_checks > 100);
  CHECK(r.conservation_violations.empty());
  REQUIRE(r.status.is_object());
  for (const auto& [type, c] : r.status["inventory"].items()) {
    INFO(type << " " << c.dump());
    CHECK(c["conserved"] == true);
  }
  for (const auto& res : r.status["resources"]) {
    INFO(res.dump());
    CHECK(res["reserved_by"] == "");
    CHECK(res["alive"] == true);
  }
  CHECK(r.holds_left == 0);
  CHECK(r.down_ok);
  std::string left;
  for (const auto& p : r.processes_left) left += p + "\n";
  INFO("processes left after cellctl down:\n" << left);
  CHECK(r.processes_left.empty());
  CHECK(r.integrity == "ok");
}
