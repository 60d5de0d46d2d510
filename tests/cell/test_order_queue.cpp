// The desk's queue: past max_twins, orders wait in the cell's state in the order they came,
// each says its place, and a cellctl up killed mid-way loses none of them.

#include <algorithm>
#include <map>
#include <memory>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "services/state/cell_store.hpp"
#include "tests/support/cell_test.hpp"
#include "tests/support/domains.hpp"

namespace domains = test::domains;

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// Waits until the journal has the event for the order.
bool journaled(const fs::path& state, const std::string& event, const std::string& order, std::chrono::seconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (fs::exists(state::CellStore::file_in(state))) {
      for (const auto& e : state::CellStore(state).journal_since(0)) {
        if (e.event == event && e.order == order) return true;
      }
    }
    std::this_thread::sleep_for(100ms);
  }
  return false;
}

// The default cell with at most `max_twins` orders under way, written into `dir`.
fs::path cell_with_max_twins(const fs::path& dir, int max_twins) {
  std::string yaml = test::read_text(DEFAULT_CELL);
  yaml.replace(yaml.find("max_twins: 16"), 13, "max_twins: " + std::to_string(max_twins));
  const fs::path cell = dir / "cell.yaml";
  std::ofstream(cell) << yaml;
  return cell;
}

}  // namespace

TEST_CASE("order queue: past max_twins orders wait in the order they came and say their places, and a killed up loses none",
          "[process][cell][desk]") {
  test::clean_stale_dds_segments();
  const fs::path dir = test::scratch("order-queue"), state = dir / "state";
  const std::string domain = domains::text(domains::kOrderQueue);
  const fs::path cell = cell_with_max_twins(dir, 2);
  const auto up_argv = [&] {
    return std::vector<std::string>{CELLCTL_EXE, "up", "--cell", cell.string(), "--domain", domain, "--real-time-factor", "10",
                                    "--state-dir", state.string()};
  };
  // Three Lego towers wait in the cell's state before it comes up (as after a day's orders came
  // in overnight); a fourth is handed over with --detach and a fifth followed by cellctl
  // submit once it is up. A factor of 10: each order holds the one station for seconds, so
  // the last ones find two under way, also under ThreadSanitizer.
  const std::string product = std::string(PRODUCTS_DIR) + "/lego-tower/lego-tower.aml";
  const std::vector<std::string> ids = {"q1", "q2", "q3", "q4", "q5"};
  const auto detach = [&](const std::string& id) {
    return test::cellctl({"submit", "--detach", product, "--cell", cell.string(), "--domain", domain, "--order", id, "--out",
                          (dir / id).string()},
                         dir / (id + ".log"), 30s);
  };
  CHECK(detach("q4") == 2);  // no cell yet to hand it to
  CHECK(test::read_text(dir / "q4.log").find("--detach hands the order to the cell of cellctl up, and none runs on domain " + domain) !=
        std::string::npos);
  {
    state::CellStore store(state);
    for (std::size_t i = 0; i < 3; ++i) {
      REQUIRE(store.submit_order({ids[i], "", "", product, (dir / ids[i]).string(), "search", "linear"}));
      store.journal("cellctl", "submitted", ids[i], product);
    }
  }
  auto up = std::make_unique<test::ChildProcess>(up_argv(), (dir / "up-1.log").string());
  REQUIRE(test::appears(dir / "up-1.log", "cell up on domain", 60s));
  REQUIRE(detach("q4") == 0);
  CHECK(test::read_text(dir / "q4.log").find("order q4 handed to the cell") != std::string::npos);
  test::ChildProcess submit({CELLCTL_EXE, "submit", product, "--cell", cell.string(), "--domain", domain, "--order", "q5",
                             "--out", (dir / "q5").string()},
                            (dir / "q5.log").string());
  REQUIRE(journaled(state, "submitted", "q5", 30s));

  // What the operator sees while orders wait: each queued one with its place, in arrival order.
  REQUIRE(journaled(state, "queued", "q5", 30s));
  REQUIRE(test::cellctl({"status", "--cell", cell.string(), "--domain", domain, "--json"}, dir / "status.json", 60s) == 0);
  const auto status = nlohmann::json::parse(test::read_text(dir / "status.json"));
  std::vector<std::pair<int, std::string>> places;
  for (const auto& o : status["orders"]) {
    if (o.contains("place")) places.emplace_back(o["place"].get<int>(), o["order"].get<std::string>());
  }
  INFO(status.dump(1));
  REQUIRE_FALSE(places.empty());
  std::sort(places.begin(), places.end());
  for (std::size_t i = 0; i < places.size(); ++i) {
    CHECK(places[i].first == static_cast<int>(i) + 1);
    if (i > 0) CHECK(places[i - 1].second < places[i].second);  // q1 < q2 < ...: the order they came in
  }
  CHECK(places.back().second == "q5");

  // cellctl up dies hard while orders run and wait; the next up takes every one up.
  REQUIRE(journaled(state, "twin started", "q3", 120s));
  const auto children = test::children_of(up->pid());
  up->kill_hard();
  for (const auto& [name, pid] : children) {
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    while (test::is_running(pid) && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(50ms);
  }
  up = std::make_unique<test::ChildProcess>(up_argv(), (dir / "up-2.log").string());
  REQUIRE(test::appears(dir / "up-2.log", "cell up on domain", 60s));

  {
    const int code = submit.wait_for_exit(180s);
    INFO(test::read_text(dir / "q5.log") << test::error_lines(test::read_text(dir / "up-2.log")));
    CHECK(code == 0);
    CHECK(test::read_text(dir / "q5.log").find("waits in the cell's queue, place") != std::string::npos);
  }

  // From the journal: each order's first twin started in arrival order, and never more than
  // max_twins orders were under way at once (from their first twin to their end).
  std::vector<std::string> first_started;
  std::map<std::string, bool> under_way;
  std::size_t most = 0;
  std::string starts_and_ends;  // what the journal said, for a failure
  for (const auto& e : state::CellStore(state).journal_since(0)) {
    if (e.event == "twin started" || e.event == "DONE" || e.event == "FAILED") {
      starts_and_ends += std::to_string(e.seq) + " " + e.order + " " + e.event + " (" + e.detail + ")\n";
    }
    if (e.event == "twin started" && !under_way.count(e.order)) {
      first_started.push_back(e.order);
      under_way[e.order] = true;
    }
    if ((e.event == "DONE" || e.event == "FAILED") && under_way.count(e.order)) under_way[e.order] = false;
    most = std::max<std::size_t>(most, std::count_if(under_way.begin(), under_way.end(), [](const auto& u) { return u.second; }));
  }
  INFO(starts_and_ends);
  CHECK(first_started == ids);
  CHECK(most <= 2);
  const auto orders = state::CellStore(state).orders();
  CHECK(orders.size() == ids.size());
  for (const auto& o : orders) {
    INFO(o.order << ": " << o.state << " " << o.reason);
    CHECK(o.state == "DONE");
  }
  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 60s) == 0);
  CHECK(up->wait_for_exit(30s) == 0);
}

TEST_CASE("cancel: a queued order never starts, one in physical assembly fails with the reason and holds nothing, "
          "and the cell builds the next", "[process][cell][desk]") {
  test::clean_stale_dds_segments();
  const fs::path dir = test::scratch("cancel"), state = dir / "state";
  const std::string domain = domains::text(domains::kCancel);
  const fs::path cell = cell_with_max_twins(dir, 1);
  test::ChildProcess up({CELLCTL_EXE, "up", "--cell", cell.string(), "--domain", domain, "--real-time-factor", "10",
                         "--state-dir", state.string()},
                        (dir / "up.log").string());
  REQUIRE(test::appears(dir / "up.log", "cell up on domain", 60s));
  const std::string product = std::string(PRODUCTS_DIR) + "/lego-tower/lego-tower.aml";
  const auto detach = [&](const std::string& id) {
    return test::cellctl({"submit", "--detach", product, "--cell", cell.string(), "--domain", domain, "--order", id, "--out",
                          (dir / id).string()},
                         dir / (id + ".log"), 30s);
  };
  const auto cancel = [&](const std::string& id) {
    return test::cellctl({"cancel", id, "--cell", cell.string(), "--domain", domain}, dir / ("cancel-" + id + ".log"), 30s);
  };
  const auto record = [&](const std::string& id) {
    for (const auto& o : state::CellStore(state).orders()) {
      if (o.order == id) return o;
    }
    return state::OrderRecord{};
  };
  const auto ends = [&](const std::string& id, std::chrono::seconds timeout) {
    for (auto until = std::chrono::steady_clock::now() + timeout; std::chrono::steady_clock::now() < until;
         std::this_thread::sleep_for(100ms)) {
      if (record(id).ended()) return true;
    }
    return false;
  };

  REQUIRE(detach("c1") == 0);
  REQUIRE(detach("c2") == 0);
  REQUIRE(journaled(state, "queued", "c2", 30s));
  CHECK(cancel("c2") == 0);
  CHECK(test::read_text(dir / "cancel-c2.log").find("it never starts") != std::string::npos);
  REQUIRE(ends("c2", 30s));
  CHECK(record("c2").state == "FAILED");
  CHECK(record("c2").reason == "cancelled by the operator (cellctl) before it started");
  CHECK(record("c2").attempts == 0);

  // c1 once its first part is in the arm's gripper.
  bool gripping = false;
  for (auto until = std::chrono::steady_clock::now() + 120s; !gripping && std::chrono::steady_clock::now() < until;
       std::this_thread::sleep_for(50ms)) {
    const auto parts = state::CellStore(state).parts("c1");
    gripping = std::any_of(parts.begin(), parts.end(), [](const state::PartRecord& p) { return p.place == state::Place::in_gripper; });
  }
  REQUIRE(gripping);
  CHECK(cancel("c1") == 0);
  REQUIRE(ends("c1", 60s));
  INFO(test::error_lines(test::read_text(dir / "up.log")));
  CHECK(record("c1").state == "FAILED");
  CHECK(record("c1").reason == "cancelled by the operator (cellctl)");
  CHECK(cancel("c1") == 1);  // ended: nothing to cancel
  CHECK(test::read_text(dir / "cancel-c1.log").find("has ended") != std::string::npos);
  CHECK(cancel("nope") == 1);
  CHECK(test::read_text(dir / "cancel-nope.log").find("no order nope") != std::string::npos);

  // Nothing of c1 holds the station: the next order is built.
  REQUIRE(detach("c3") == 0);
  REQUIRE(ends("c3", 120s));
  CHECK(record("c3").state == "DONE");
  for (const auto& [type, c] : state::CellStore(state).inventory()) {
    INFO(type);
    CHECK(c.initial == c.accounted());
  }
  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 60s) == 0);
  CHECK(up.wait_for_exit(30s) == 0);
}

TEST_CASE("cancel: an order whose twin is still planning ends within seconds of the ask, not when its planning would",
          "[process][cell][desk]") {
  test::clean_stale_dds_segments();
  const fs::path dir = test::scratch("cancel-planning"), state = dir / "state";
  const std::string domain = domains::text(domains::kCancelWhilePlanning);
  test::ChildProcess up({CELLCTL_EXE, "up", "--domain", domain, "--real-time-factor", "10", "--state-dir", state.string()},
                        (dir / "up.log").string());
  REQUIRE(test::appears(dir / "up.log", "cell up on domain", 60s));
  // A real box whose planning takes half a minute in Release (every orientation searched to
  // its end: docs/performance.md), far longer under a sanitizer.
  const std::string product = std::string(REAL_DATA_DIR) + "/ikea-box_ivar_0666/ikea-box_ivar_0666.aml";
  REQUIRE(test::cellctl({"submit", "--detach", product, "--domain", domain, "--order", "p1", "--out", (dir / "p1").string()},
                        dir / "p1.log", 30s) == 0);
  REQUIRE(journaled(state, "twin started", "p1", 30s));
  std::this_thread::sleep_for(2s);  // well into its planning
  const auto asked = std::chrono::steady_clock::now();
  REQUIRE(test::cellctl({"cancel", "p1", "--domain", domain}, dir / "cancel.log", 30s) == 0);
  state::OrderRecord p1;
  for (auto until = asked + 60s; std::chrono::steady_clock::now() < until && !p1.ended(); std::this_thread::sleep_for(100ms)) {
    for (const auto& o : state::CellStore(state).orders()) {
      if (o.order == "p1") p1 = o;
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - asked).count();
  INFO(test::error_lines(test::read_text(dir / "up.log")) << "ended " << seconds << " s after the ask");
  REQUIRE(p1.ended());
  CHECK(p1.state == "FAILED");
  // A twin that heard the ask only after planning would end with what planning found.
  CHECK(p1.reason == "cancelled by the operator (cellctl)");
  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 60s) == 0);
  CHECK(up.wait_for_exit(30s) == 0);
}
