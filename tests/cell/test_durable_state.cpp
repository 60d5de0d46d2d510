// The cell's durable state under kills: cellctl up restarts what dies, the restarted
// processes take up the state where their predecessors left it, and every part is accounted
// for at every moment `cellctl status --json` is read.

#include <signal.h>

#include <fstream>
#include <functional>
#include <set>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "services/state/cell_store.hpp"
#include "tests/support/cell_test.hpp"
#include "tests/support/domains.hpp"
#include "tests/support/order_twins.hpp"

namespace domains = test::domains;

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using nlohmann::json;


json status_json(const std::string& domain, const fs::path& dir) {
  const fs::path out = dir / "status.json";
  REQUIRE(test::cellctl({"status", "--json", "--domain", domain}, out, 30s) == 0);
  return json::parse(test::read_text(out));
}

void check_conserved(const json& status) {
  REQUIRE(!status["inventory"].empty());
  for (const auto& [type, c] : status["inventory"].items()) {
    INFO(type << ": " << c.dump());
    CHECK(c["initial"].get<int>() == c["in_buffers"].get<int>() + c["assembled"].get<int>() +
                                         c["on_stations"].get<int>() + c["in_transit"].get<int>() +
                                         c["inspection"].get<int>());
    CHECK(c["conserved"] == true);
  }
}

const json& resource(const json& status, const std::string& id) {
  for (const auto& r : status["resources"]) {
    if (r["id"] == id) return r;
  }
  FAIL("no resource " << id << " in " << status.dump());
  throw std::logic_error("unreachable");
}

// Kills the cell process of cellctl up named by `argument` and waits for its restart.
void kill_and_wait_restart(pid_t up, const std::string& argument, const fs::path& log, int restart) {
  const pid_t pid = test::child_with_argument(up, argument);
  REQUIRE(pid > 0);
  const std::size_t before_kill = test::read_text(log).size();
  ::kill(pid, SIGKILL);
  REQUIRE(test::appears(log, argument + " restarted (pid", std::chrono::seconds(30), before_kill));
  REQUIRE(test::appears(log, "restart " + std::to_string(restart) + ")", std::chrono::seconds(30), before_kill));
}

}  // namespace

TEST_CASE("kills mid-order: the order is taken up, every part accounted for, stock kept across a restart",
          "[process][cell][state]") {
  test::clean_stale_dds_segments();
  const fs::path dir = test::scratch("durable-state");
  const fs::path state_dir = dir / "state", log = dir / "up.log";
  const std::string domain = domains::text(domains::kKillsMidOrder);
  const std::string lego = std::string(PRODUCTS_DIR) + "/lego-tower/lego-tower.aml";
  test::ChildProcess up({CELLCTL_EXE, "up", "--domain", domain, "--real-time-factor", "20", "--state-dir",
                         state_dir.string()},
                        log.string());
  REQUIRE(test::appears(log, "cell up on domain"));

  // An order under way when its mobile robot dies.
  test::ChildProcess first({CELLCTL_EXE, "submit", lego, "--domain", domain, "--order", "first", "--out",
                            (dir / "first").string()},
                           (dir / "first.log").string());
  {
    state::CellStore store(state_dir);
    const auto deadline = std::chrono::steady_clock::now() + 90s;
    while (store.parts("first").size() < 2 && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(20ms);
    REQUIRE(store.parts("first").size() >= 2);  // the robot has parts under way
  }
  kill_and_wait_restart(up.pid(), "mobile-robot-1", log, 1);
  const int first_exit = first.wait_for_exit(120s);
  INFO("first's last lines:\n" << test::last_lines(dir / "first.log", 4) << "up's last lines:\n" << test::last_lines(log, 12));
  CHECK(first_exit == 0);  // its twin ended for the next one, which took the order up
  json status = status_json(domain, dir);
  check_conserved(status);
  REQUIRE(status["orders"].size() == 1);
  CHECK(status["orders"][0]["order"] == "first");
  CHECK(status["orders"][0]["state"] == "DONE");

  // The bricks' buffer dies: the process after it has the stored stock, not the file's.
  kill_and_wait_restart(up.pid(), "buffer-2", log, 1);
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  do {
    status = status_json(domain, dir);
  } while (!resource(status, "buffer-2")["alive"].get<bool>() && std::chrono::steady_clock::now() < deadline);
  INFO(status.dump(1));
  const json& buffer = resource(status, "buffer-2");
  REQUIRE(buffer["alive"] == true);
  CHECK(buffer["restarts"] == 1);
  CHECK(resource(status, "mobile-robot-1")["restarts"] == 1);
  for (const auto& [type, count] : buffer["stock"].items()) {
    INFO(type);
    CHECK(count == status["inventory"][type]["in_buffers"]);
  }
  CHECK(buffer["stock"]["Brick2x4"].get<int>() < 120);  // the first order took some

  // And the cell assembles the next order.
  CHECK(test::cellctl({"submit", lego, "--domain", domain, "--order", "second", "--out", (dir / "second").string()},
                      dir / "second.log") == 0);
  status = status_json(domain, dir);
  check_conserved(status);
  for (const auto& r : status["resources"]) CHECK(r["reserved_by"] == "");

  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 30s) == 0);
  CHECK(up.wait_for_exit(20s) == 0);
  CHECK(test::children_of(up.pid()).empty());
  state::CellStore store(state_dir);
  CHECK(store.integrity() == "ok");
  CHECK(store.holders().empty());
  CHECK(store.count_events("mobile-robot-1", "restarted") == 1);
}

namespace {

// Waits until `count` parts of the order stand in place; those parts.
std::set<std::string> wait_for_placed(const fs::path& state_dir, const std::string& order, std::size_t count) {
  state::CellStore store(state_dir);
  std::set<std::string> placed;
  const auto deadline = std::chrono::steady_clock::now() + 90s;
  while (placed.size() < count && std::chrono::steady_clock::now() < deadline) {
    placed.clear();
    for (const auto& p : store.parts(order)) {
      if (p.place == state::Place::placed) placed.insert(p.part);
    }
    std::this_thread::sleep_for(20ms);
  }
  return placed;
}

// Every part in place before stays the one assembled: none was fetched or placed again.
void check_taken_up(const fs::path& state_dir, const std::string& order, const std::set<std::string>& placed_before,
                    std::size_t parts) {
  state::CellStore store(state_dir);
  std::set<std::string> assembled, all;
  for (const auto& p : store.parts(order)) {
    all.insert(p.part);
    if (p.place == state::Place::assembled) assembled.insert(p.part);
  }
  INFO("parts of " << order << ": " << all.size());
  CHECK(assembled.size() == parts);
  for (const auto& part : placed_before) {
    INFO(part);
    CHECK(assembled.count(part) == 1);
    CHECK(all.count(part + "/r2") == 0);
  }
  bool taken_up = false, plan_followed = false;
  for (const auto& e : store.journal_since(0)) {
    taken_up |= e.order == order && e.event == "taken up";
    plan_followed |= e.order == order && e.event == "plan followed";  // the order its predecessor began
  }
  CHECK(taken_up);
  CHECK(plan_followed);
  CHECK(store.plan_of(order).size() >= parts);
  for (const auto& [type, c] : store.inventory()) CHECK(c.initial == c.accounted());
}

// A Lego tower submitted to `cellctl up` (with `up_args` more), its twin sent `signal` once
// three parts are placed: the order must end assembled, taken up by the next twin, no step
// done twice. `then` is asked before the cell goes down, with up's log and the first twin's pid.
void twin_signalled_mid_order(const std::string& name, const std::string& domain, int signal,
                              const std::vector<std::string>& up_args,
                              const std::function<void(const fs::path& dir, const std::string& log, pid_t twin)>& then) {
  test::clean_stale_dds_segments();
  const fs::path dir = test::scratch(name);
  const fs::path state_dir = dir / "state", log = dir / "up.log";
  std::vector<std::string> up_argv{CELLCTL_EXE, "up", "--domain", domain, "--real-time-factor", "10", "--state-dir",
                                   state_dir.string()};
  up_argv.insert(up_argv.end(), up_args.begin(), up_args.end());
  test::ChildProcess up(up_argv, log.string());
  REQUIRE(test::appears(log, "cell up on domain"));
  test::ChildProcess submit({CELLCTL_EXE, "submit", std::string(PRODUCTS_DIR) + "/lego-tower/lego-tower.aml", "--domain",
                             domain, "--order", "tower", "--out", (dir / "tower").string()},
                            (dir / "submit.log").string());
  const auto placed = wait_for_placed(state_dir, "tower", 3);
  REQUIRE(placed.size() >= 3);
  const pid_t twin = test::twin_of(state::CellStore(state_dir), "tower");
  REQUIRE(twin > 0);
  ::kill(twin, signal);
  const int code = submit.wait_for_exit(150s);
  INFO(test::last_lines(dir / "submit.log", 6) << test::last_lines(log, 20));
  CHECK(code == 0);
  const std::string said = test::read_text(log);
  CHECK(said.find("order tower: twin started again (attempt 2)") != std::string::npos);
  check_taken_up(state_dir, "tower", placed, 11);
  then(dir, said, twin);
  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 30s) == 0);
  CHECK(up.wait_for_exit(20s) == 0);
}

}  // namespace

TEST_CASE("a twin killed during physical assembly is started again and finishes the order, no step done twice",
          "[process][cell][state]") {
  const std::string domain = domains::text(domains::kTwinResumes);
  twin_signalled_mid_order("twin-resume", domain, SIGKILL, {}, [&](const fs::path& dir, const std::string&, pid_t) {
    const json status = status_json(domain, dir);
    for (const auto& r : status["resources"]) CHECK(r["reserved_by"] == "");
  });
}

TEST_CASE("a twin frozen during physical assembly falls silent: the desk ends it, and the next one finishes the order",
          "[process][cell][state]") {
  const fs::path cell = test::scratch("twin-frozen-cell") / "cell.yaml";
  std::ofstream(cell) << test::read_text(fs::path(DEPLOY_CELLS) / "default.yaml") << "\ntwin_watchdog: 5\n";
  // SIGSTOP: alive on DDS for its lease, its loop stopped: only its heartbeat tells.
  twin_signalled_mid_order("twin-frozen", domains::text(domains::kTwinFrozenDesk), SIGSTOP, {"--cell", cell.string()},
                           [](const fs::path&, const std::string& log, pid_t twin) {
                             CHECK(log.find("the twin of order tower runs but its heartbeat stopped") != std::string::npos);
                             CHECK(::kill(twin, 0) != 0);  // ended, not left stopped
                           });
}

TEST_CASE("a twin killed once a subassembly stands built aside: the next one inserts it as it stands",
          "[process][cell][state][subassembly]") {
  test::clean_stale_dds_segments();
  const fs::path dir = test::scratch("subassembly-resume");
  const fs::path state_dir = dir / "state", log = dir / "up.log";
  const std::string domain = domains::text(domains::kSubassemblyResumed);
  test::ChildProcess up({CELLCTL_EXE, "up", "--domain", domain, "--real-time-factor", "10", "--state-dir",
                         state_dir.string()},
                        log.string());
  REQUIRE(test::appears(log, "cell up on domain"));
  test::ChildProcess submit({CELLCTL_EXE, "submit",
                             std::string(TEST_DATA_DIR) + "/planning/cranfield-subassembly/cranfield-subassembly.aml",
                             "--domain", domain, "--order", "nested", "--out", (dir / "nested").string()},
                            (dir / "submit.log").string());
  // The plan's first two steps build shaft and pendulum aside.
  const auto aside = wait_for_placed(state_dir, "nested", 2);
  REQUIRE(aside.size() >= 2);
  const pid_t twin = test::twin_of(state::CellStore(state_dir), "nested");
  REQUIRE(twin > 0);
  ::kill(twin, SIGKILL);
  {
    state::CellStore store(state_dir);
    std::size_t in_subassembly = 0;
    for (const auto& p : store.parts("nested")) in_subassembly += p.place == state::Place::placed && p.holder == "ShaftPendulum";
    CHECK(in_subassembly >= 1);  // the state knows they stand aside, not in the product
  }
  const int code = submit.wait_for_exit(150s);
  INFO(test::read_text(dir / "submit.log") << test::read_text(log));
  CHECK(code == 0);
  CHECK(test::read_text(log).find("order nested: twin started again (attempt 2)") != std::string::npos);
  check_taken_up(state_dir, "nested", aside, 9);
  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 30s) == 0);
  CHECK(up.wait_for_exit(20s) == 0);
}

TEST_CASE("cellctl down pauses the orders under way, and up on the same state takes them up", "[process][cell][state]") {
  test::clean_stale_dds_segments();
  const fs::path dir = test::scratch("pause");
  const fs::path state_dir = dir / "state";
  const std::string domain = domains::text(domains::kDownPauses);
  const std::vector<std::string> up_args{CELLCTL_EXE, "up", "--domain", domain, "--real-time-factor", "10",
                                         "--state-dir", state_dir.string()};
  auto up = std::make_unique<test::ChildProcess>(up_args, (dir / "up-1.log").string());
  REQUIRE(test::appears(dir / "up-1.log", "cell up on domain"));
  test::ChildProcess submit({CELLCTL_EXE, "submit", std::string(PRODUCTS_DIR) + "/lego-tower/lego-tower.aml", "--domain",
                             domain, "--order", "paused", "--out", (dir / "paused").string()},
                            (dir / "submit.log").string());
  const auto placed = wait_for_placed(state_dir, "paused", 2);
  REQUIRE(placed.size() >= 2);
  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down-1.log", 30s) == 0);
  CHECK(up->wait_for_exit(20s) == 0);
  {
    state::CellStore store(state_dir);
    const auto orders = store.orders();
    REQUIRE(orders.size() == 1);
    CHECK(orders.front().state == "INTERRUPTED");
  }
  up = std::make_unique<test::ChildProcess>(up_args, (dir / "up-2.log").string());
  const int code = submit.wait_for_exit(150s);  // it follows the order across the pause
  INFO(test::read_text(dir / "submit.log") << test::read_text(dir / "up-1.log") << test::read_text(dir / "up-2.log"));
  CHECK(code == 0);
  check_taken_up(state_dir, "paused", placed, 11);
  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down-2.log", 30s) == 0);
  CHECK(up->wait_for_exit(20s) == 0);
}
