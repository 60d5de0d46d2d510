// cellctl up as a supervisor: a cell process that dies is started again and the cell goes
// on; one that keeps dying is given up on, and the cell stops with the reason.

#include <signal.h>

#include <fstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "services/state/cell_store.hpp"
#include "tests/support/cell_test.hpp"
#include "tests/support/domains.hpp"

namespace domains = test::domains;

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;


}  // namespace

TEST_CASE("cellctl up restarts a process that dies, and gives up on one that keeps dying", "[process][cell]") {
  const fs::path dir = test::scratch("supervision");
  // The default cell on a domain of its own, allowed two restarts of a process a minute.
  const fs::path cell = dir / "cell.yaml";
  std::ofstream(cell) << test::read_text(DEFAULT_CELL) << "\nrestart: {limit: 2, window: 60}\n";
  const std::string domain = domains::text(domains::kUpRestarts);
  const fs::path log = dir / "up.log";
  test::ChildProcess up({CELLCTL_EXE, "up", cell.string(), "--domain", domain, "--state-dir", (dir / "state").string()},
                        log.string());
  REQUIRE(test::appears(log, "cell up on domain"));

  // buffer-2 (the Lego bricks) dies hard: it is back, and a Lego order is assembled.
  const pid_t first = test::child_with_argument(up.pid(), "buffer-2");
  REQUIRE(first > 0);
  const std::size_t before_kill = test::read_text(log).size();
  ::kill(first, SIGKILL);
  REQUIRE(test::appears(log, "buffer-2 ended (exit 137); restarting it in 500 ms", 30s, before_kill));
  REQUIRE(test::appears(log, "buffer-2 restarted", 30s, before_kill));
  const int order = test::cellctl({"submit", std::string(PRODUCTS_DIR) + "/lego-tower/lego-tower.aml", "--domain",
                                   domain, "--order", "after-restart", "--out", (dir / "after-restart").string()},
                                  dir / "order.log");
  INFO(test::read_text(dir / "order.log") << test::read_text(log));
  CHECK(order == 0);

  // Twice more within the minute: the third end is one too many.
  for (int kill = 2; kill <= 3; ++kill) {
    pid_t pid = 0;
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    while ((pid = test::child_with_argument(up.pid(), "buffer-2")) == 0 && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(50ms);
    }
    REQUIRE(pid > 0);
    ::kill(pid, SIGKILL);
    if (kill == 2) REQUIRE(test::appears(log, "restart 2)"));
  }
  CHECK(up.wait_for_exit(30s) == 1);
  CHECK(test::read_text(log).find("error: buffer-2 ended 3 times within 60 s, last with exit 137; stopping the cell") !=
        std::string::npos);
  // The journal keeps the reason for whoever reads the state later.
  bool journaled = false;
  for (const auto& e : state::CellStore(dir / "state").journal_since(0)) {
    journaled |= e.event == "down" && e.detail.find("gave up: buffer-2 ended 3 times within 60 s") != std::string::npos;
  }
  CHECK(journaled);
  CHECK(test::children_of(up.pid()).empty());
}

TEST_CASE("cellctl up ends and restarts a process that runs but is not heard (a hung one), and the cell goes on",
          "[process][cell]") {
  const fs::path dir = test::scratch("unheard");
  const std::string domain = domains::text(domains::kUpHung);
  const fs::path log = dir / "up.log";
  // --wait: how long a process may go unheard, here 5 s after its 5 s liveliness lease.
  test::ChildProcess up({CELLCTL_EXE, "up", "--domain", domain, "--wait", "5", "--state-dir", (dir / "state").string()},
                        log.string());
  REQUIRE(test::appears(log, "cell up on domain"));

  // buffer-2 hangs: it runs, its loop beats no more, and it says nothing on DDS. Its
  // heartbeat stops first (its lease on DDS runs 5 s longer).
  const pid_t hung = test::child_with_argument(up.pid(), "buffer-2");
  REQUIRE(hung > 0);
  // Under TSan beside other tests, a process may have been restarted at start-up already
  // (unheard on DDS within --wait): what counts comes after the hang.
  const std::size_t before_hang = test::read_text(log).size();
  ::kill(hung, SIGSTOP);
  REQUIRE(test::appears(log, "buffer-2 runs but its heartbeat stopped", 60s, before_hang));
  REQUIRE(test::appears(log, "buffer-2 restarted", 30s, before_hang));
  CHECK_FALSE(test::is_running(hung));
  const int order = test::cellctl({"submit", std::string(PRODUCTS_DIR) + "/lego-tower/lego-tower.aml", "--domain",
                                   domain, "--order", "after-hang", "--out", (dir / "after-hang").string()},
                                  dir / "order.log");
  INFO(test::read_text(dir / "order.log") << test::read_text(log));
  CHECK(order == 0);
  bool journaled = false;
  for (const auto& e : state::CellStore(dir / "state").journal_since(0)) journaled |= e.event == "unheard" && e.source == "buffer-2";
  CHECK(journaled);
  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 60s) == 0);
  CHECK(up.wait_for_exit(30s) == 0);
}

TEST_CASE("cellctl up with two discovery servers: one killed is started again, and while one is stopped new twins and "
          "clients find the cell through the other",
          "[process][cell][discovery]") {
  const fs::path dir = test::scratch("two-servers");
  const std::string domain = domains::text(domains::kTwoDiscoveryServers);
  const fs::path cell = dir / "cell.yaml", log = dir / "up.log";
  std::ofstream(cell) << test::read_text(DEFAULT_CELL) << "\ndiscovery: {servers: [127.0.0.1:12406, 127.0.0.1:12407]}\n";
  test::ChildProcess up({CELLCTL_EXE, "up", cell.string(), "--domain", domain, "--real-time-factor", "50", "--state-dir",
                         (dir / "state").string()},
                        log.string());
  REQUIRE(test::appears(log, "cell up on domain"));
  // The first server: the child whose command line has `--serve 0`.
  const auto server_0 = [&] {
    for (const auto& [name, pid] : test::children_of(up.pid())) {
      std::ifstream in("/proc/" + std::to_string(pid) + "/cmdline", std::ios::binary);
      std::vector<std::string> args;
      for (std::string arg; std::getline(in, arg, '\0');) args.push_back(arg);
      for (std::size_t i = 0; i + 1 < args.size(); ++i) {
        if (args[i] == "--serve" && args[i + 1] == "0") return pid;
      }
    }
    return pid_t{0};
  };
  const auto order = [&](const std::string& product, const std::string& id) {
    const int code = test::cellctl({"submit", std::string(PRODUCTS_DIR) + "/" + product, "--domain", domain, "--order", id,
                                    "--out", (dir / id).string()},
                                   dir / (id + ".log"));
    INFO(test::read_text(dir / (id + ".log")) << test::read_text(log));
    CHECK(code == 0);
  };

  const pid_t killed = server_0();
  REQUIRE(killed > 0);
  const std::size_t before_kill = test::read_text(log).size();
  ::kill(killed, SIGKILL);
  REQUIRE(test::appears(log, "discovery-0 ended (exit 137); restarting it", 30s, before_kill));
  REQUIRE(test::appears(log, "discovery-0 restarted", 30s, before_kill));
  order("lego-tower/lego-tower.aml", "after-kill");

  // Stopped, not ended: the cell runs on through the other server. Two orders, so that the
  // second is taken by a twin started while the first server was stopped.
  const pid_t stopped = server_0();
  REQUIRE(stopped > 0);
  REQUIRE(stopped != killed);
  ::kill(stopped, SIGSTOP);
  order("lego-tower/lego-tower.aml", "stopped-1");
  order("cranfield/cranfield.aml", "stopped-2");
  ::kill(stopped, SIGCONT);
  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 60s) == 0);
  CHECK(up.wait_for_exit(30s) == 0);
}

TEST_CASE("cellctl up: one cell per domain, and after an up that was killed, down says so and up starts afresh",
          "[process][cell]") {
  const fs::path dir = test::scratch("up-killed");
  const std::string domain = domains::text(domains::kOneCellPerDomain);
  const fs::path log = dir / "up.log";
  auto up = std::make_unique<test::ChildProcess>(std::vector<std::string>{CELLCTL_EXE, "up", "--domain", domain, "--state-dir", (dir / "state").string()},
                                                 log.string());
  REQUIRE(test::appears(log, "cell up on domain"));
  CHECK(test::cellctl({"up", "--domain", domain}, dir / "second.log", 30s) == 1);
  CHECK(test::read_text(dir / "second.log").find("a cell runs on domain " + domain + " already") != std::string::npos);

  // cellctl up dies hard: its processes end with it (they asked for SIGTERM when their parent goes).
  const auto children = test::children_of(up->pid());
  std::string names;
  for (const auto& [name, pid] : children) names += name + " (pid " + std::to_string(pid) + ")\n";
  INFO(names);
  REQUIRE(children.size() == 6);  // cell-sim, the station, the robot, two buffers, a standby twin
  up->kill_hard();
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  const auto any_left = [&] {
    for (const auto& [name, pid] : children) {
      if (test::is_running(pid)) return true;
    }
    return false;
  };
  while (any_left() && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(50ms);
  for (const auto& [name, pid] : children) {
    INFO(name << " (pid " << pid << ") still runs: " << test::read_text("/proc/" + std::to_string(pid) + "/stat"));
    CHECK_FALSE(test::is_running(pid));
  }

  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 30s) == 1);
  CHECK(test::read_text(dir / "down.log").find("its cellctl up was killed") != std::string::npos);
  up = std::make_unique<test::ChildProcess>(std::vector<std::string>{CELLCTL_EXE, "up", "--domain", domain, "--state-dir", (dir / "state").string()},
                                            (dir / "again.log").string());
  REQUIRE(test::appears(dir / "again.log", "cell up on domain"));
  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down2.log", 30s) == 0);
  CHECK(up->wait_for_exit(20s) == 0);
}

TEST_CASE("cellctl up refuses a cell that would pass a limit of the host, says which and what to change, and starts nothing",
          "[process][cell]") {
  const fs::path dir = test::scratch("too-many-twins");
  std::string yaml = test::read_text(DEFAULT_CELL);
  yaml.replace(yaml.find("max_twins: 16"), 13, "max_twins: 40");
  const fs::path cell = dir / "cell.yaml";
  std::ofstream(cell) << yaml;
  CHECK(test::cellctl({"up", cell.string(), "--domain", domains::text(domains::kUpPastAHostLimit), "--state-dir",
                       (dir / "state").string()},
                      dir / "up.log", 30s) == 2);
  const std::string log = test::read_text(dir / "up.log");
  INFO(log);
  CHECK(log.find("47 DDS participants on this host (5 processes, 40 twins at once, 1 standing by, cellctl) pass the 28 that "
                 "simple discovery finds: set `discovery: server`, or lower max_twins") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "state"));
}
