// What DDS-Security costs, with it off and on in the same run (docs/performance.md):
//  1. a command's round trip to a buffer process until SUCCEEDED (hired as a twin hires it,
//     sent as the mobile robot sends gives: the identities `twin-1` and `mobile-robot-1`);
//  2. a twin's start to its first status, and to virtual assembly begun (Cranfield, with
//     cell-sim and a station running), started with its order and as a standby twin;
//  3. `cellctl run` of Cranfield on the default cell, wall time from start to end.
// Run: build/release/bin/bench_security [--rounds N] [--launches N] [--runs N]

#include <cstring>
#include <filesystem>
#include <fstream>

#include "commandsPubSubTypes.h"
#include "tests/bench/bench_support.hpp"
#include "tests/bench/twin_launches.hpp"
#include "tests/support/cell_test.hpp"
#include "tests/support/hire.hpp"

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using bench::Clock;
using bench::report;

const int kDomain = 205;

struct Mode {
  std::string name;
  fs::path pki;  // empty: off
  dds::ParticipantSettings as(const std::string& identity) const {
    dds::ParticipantSettings s{kDomain, true, {}};
    if (!pki.empty()) s.security = {pki, identity};
    return s;
  }
  std::vector<std::string> args() const {
    return pki.empty() ? std::vector<std::string>{} : std::vector<std::string>{"--security", pki.string()};
  }
  std::vector<std::string> with(std::vector<std::string> argv) const {
    const auto extra = args();
    argv.insert(argv.end(), extra.begin(), extra.end());
    return argv;
  }
};

void command_round_trips(const Mode& m, int rounds) {
  test::ChildProcess buffer(m.with({BUFFER_EXE, "--id", "bench-buffer", "--domain", std::to_string(kDomain), "--stock",
                                    "Part=1000000"}),
                            "/dev/null");
  // The hirer is a twin: its order bound to its identity first, as cellctl does.
  auto binder = dds::make_participant("bench-binder", m.as("cellctl"));
  cellctl::TwinIdentities ids(m.pki.empty() ? std::vector<std::string>{} : std::vector<std::string>{"twin-1"}, binder);
  ids.bind("bench", "twin-1");
  auto hirer = dds::make_participant("bench-twin", m.as("twin-1"));
  auto sender = dds::make_participant("bench-robot", m.as("mobile-robot-1"));
  std::string why;
  const std::string award = test::hire(hirer, "bench-buffer", "bench", "give", {"", "Part", rounds + 20}, &why);
  if (award.empty()) throw std::runtime_error("cannot hire bench-buffer: " + why);
  const auto us = bench::round_trips(sender, sender, dds::command_topic("bench-buffer"), "cell/command_events", rounds, [&](int i) {
    cell::Command c;
    c.command_id("give-" + std::to_string(i));
    c.resource_id("bench-buffer");
    c.order_id("bench");
    c.award(award);
    c.operation("give");
    c.part_type("Part");
    c.destination("mobile-robot-1");
    return c;
  }, dds::owned_by({"mobile-robot-1"}));
  report("security " + m.name + ": command to SUCCEEDED, buffer process", us);
  buffer.stop();
}

void twin_starts(const Mode& m, int launches) {
  const std::string domain = std::to_string(kDomain);
  test::ChildProcess sim(m.with({CELL_SIM_EXE, "--domain", domain}), "/dev/null");
  test::ChildProcess station(m.with({STATION_EXE, "--domain", domain, "--id", "station-1"}), "/dev/null");
  auto observer = dds::make_participant("bench-observer", m.as("cellctl"));
  const auto twin = m.with({TWIN_EXE, "--domain", domain, "--quiet"});
  const std::vector<std::string> ids = m.pki.empty() ? std::vector<std::string>{} : std::vector<std::string>{"twin-1", "twin-2"};
  report("security " + m.name + ": twin start", bench::twin_launches(observer, twin, launches, false, m.name, ids));
  report("security " + m.name + ": standby twin", bench::twin_launches(observer, twin, launches, true, m.name, ids));
  station.stop();
  sim.stop();
}

void cranfield_runs(const Mode& m, const fs::path& cell, int runs) {
  std::vector<double> us;
  for (int i = 0; i < runs; ++i) {
    const auto start = Clock::now();
    const int code = test::cellctl(m.with({"run", std::string(PRODUCTS_DIR) + "/cranfield/cranfield.aml", "--cell", cell.string(),
                                           "--domain", std::to_string(kDomain), "--real-time-factor", "50", "--out",
                                           "/tmp/bench-security-run"}),
                                   "/tmp/bench-security-run.log", 300s);
    if (code != 0) throw std::runtime_error("cellctl run ended with " + std::to_string(code) + "; /tmp/bench-security-run.log");
    us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
  }
  report("security " + m.name + ": cellctl run Cranfield, 50x, wall time", us);
}

}  // namespace

int main(int argc, char** argv) {
  int rounds = 500, launches = 20, runs = 3;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--rounds") == 0) rounds = std::stoi(argv[i + 1]);
    if (std::strcmp(argv[i], "--launches") == 0) launches = std::stoi(argv[i + 1]);
    if (std::strcmp(argv[i], "--runs") == 0) runs = std::stoi(argv[i + 1]);
  }
  test::clean_stale_dds_segments();
  try {
    // The default cell with the bench's buffer, and its identities.
    const fs::path dir = test::scratch("bench-security");
    std::string yaml = test::read_text(DEFAULT_CELL);
    yaml.replace(yaml.find("buffers:\n"), 9, "buffers:\n  - id: bench-buffer\n    position: [3.0, 0, 0]\n    stock: {Part: 10}\n");
    std::ofstream(dir / "cell.yaml") << yaml;
    if (test::cellctl({"pki", "init", (dir / "pki").string(), "--cell", (dir / "cell.yaml").string(), "--domain",
                       std::to_string(kDomain)},
                      dir / "pki.log") != 0) {
      throw std::runtime_error("cellctl pki init failed: " + (dir / "pki.log").string());
    }
    for (const Mode& m : {Mode{"off", {}}, Mode{"on", dir / "pki"}}) {
      command_round_trips(m, rounds);
      twin_starts(m, launches);
      cranfield_runs(m, DEFAULT_CELL, runs);
    }
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
