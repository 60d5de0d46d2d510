// The cell's durable state under kills: cellctl up restarts what dies, the restarted
// processes take up the state where their predecessors left it, and every part is accounted
// for at every moment `cellctl status --json` is read.

#include <signal.h>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "services/state/cell_store.hpp"
#include "tests/support/cell_test.hpp"

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using nlohmann::json;

bool appears(const fs::path& file, const std::string& text, std::chrono::seconds timeout = 30s) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (test::read_text(file).find(text) != std::string::npos) return true;
    std::this_thread::sleep_for(50ms);
  }
  return false;
}

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
  ::kill(pid, SIGKILL);
  REQUIRE(appears(log, argument + " restarted (pid"));
  REQUIRE(appears(log, "restart " + std::to_string(restart) + ")"));
}

}  // namespace

TEST_CASE("kills mid-order: every part accounted for, stock kept across a restart, the cell heals",
          "[process][cell][state]") {
  test::clean_stale_dds_segments();
  const fs::path dir = test::scratch("durable-state");
  const fs::path state_dir = dir / "state", log = dir / "up.log";
  const std::string domain = "195", lego = std::string(PRODUCTS_DIR) + "/lego-tower/lego-tower.aml";
  test::ChildProcess up({CELLCTL_EXE, "up", "--domain", domain, "--real-time-factor", "20", "--state-dir",
                         state_dir.string()},
                        log.string());
  REQUIRE(appears(log, "cell up on domain"));

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
  INFO(test::read_text(dir / "first.log") << test::read_text(log));
  CHECK((first_exit == 0 || first_exit == 1));
  json status = status_json(domain, dir);
  check_conserved(status);
  REQUIRE(status["orders"].size() == 1);
  const json& order = status["orders"][0];
  CHECK(order["order"] == "first");
  if (first_exit == 0) {
    CHECK(order["state"] == "DONE");
  } else {
    CHECK(order["state"] == "FAILED");
    CHECK(order["reason"].get<std::string>().size() > 10);
  }

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
