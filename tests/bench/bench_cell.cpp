// Benchmarks of the distributed cell, between real processes on one host (localhost-only DDS):
//  1. a bare Fast DDS ping-pong (the project's typed writer and reader, the events QoS, no
//     function blocks) between this process and an echo child;
//  2. a command's round trip from a sender to a resource process (a buffer: commands topic,
//     function-block resource, life cycle, command events) until SUCCEEDED;
//  3. the time from starting a twin to its first status, and to it having planned, heard
//     cell-sim answer and begun virtual assembly (over --launches twin starts), and the
//     same from handing an order to a standby twin (deploy/cellctl/twin_pool.hpp);
//  4. 1 and 2 again while `cellctl run` assembles 10 orders on the default cell.
// Prints p50 and p99 of each. Run: build/release/bin/bench_cell [--rounds N] [--launches N]
//   (internal: bench_cell --echo DOMAIN is the ping-pong's other side)

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstring>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commandsPubSubTypes.h"
#include "services/dds/endpoints.hpp"
#include "tests/bench/bench_support.hpp"
#include "tests/bench/twin_launches.hpp"
#include "tests/support/child_process.hpp"
#include "tests/support/hire.hpp"

namespace {

using namespace std::chrono_literals;
using bench::Clock;
using bench::report;

// Set by a signal handler, read by the resources' threads: a lock-free atomic is safe for both.
std::atomic<bool> running{true};
void stop(int) { running = false; }

using EventWriter = dds::Writer<cell::CommandEvent, cell::CommandEventPubSubType>;
using CommandReader = dds::Reader<cell::Command, cell::CommandPubSubType>;

int echo(int domain) {
  std::signal(SIGTERM, stop);
  auto participant = dds::make_participant("bench-echo", {domain, true, {}});
  EventWriter pong(participant, "bench/pong", dds::TopicKind::events);
  CommandReader ping(participant, "bench/ping", dds::TopicKind::events, [&](const cell::Command& c) {
    cell::CommandEvent e;
    e.command_id(c.command_id());
    e.state(cell::SUCCEEDED);
    pong.write(e);
  });
  while (running) std::this_thread::sleep_for(50ms);
  return 0;
}

// The i-th command to `resource`; `award`: what the command names (a resource obeys only the
// order that hired it).
cell::Command command(const std::string& resource, const std::string& award, int i) {
  cell::Command c;
  c.command_id(resource + "-" + std::to_string(i));
  c.resource_id(resource);
  c.order_id("bench");
  c.award(award);
  c.operation("give");
  c.part_type("Part");
  c.destination("bench");  // a give names who takes the part
  return c;
}

// Sends `rounds` commands on `topic`, each after the answer to the one before.
std::vector<double> round_trips(const dds::ParticipantPtr& participant, const std::string& topic,
                                const std::string& answers_topic, const std::string& resource, int rounds,
                                const std::string& award = "") {
  return bench::round_trips(participant, participant, topic, answers_topic, rounds,
                            [&](int i) { return command(resource, award, i); });
}

// With cell-sim and a station running (the twin needs both before virtual assembly): twins
// started with their orders, then standby twins handed theirs.
void twin_start(int domain, int rounds) {
  test::ChildProcess sim({CELL_SIM_EXE, "--domain", std::to_string(domain)}, "/dev/null");
  test::ChildProcess station({STATION_EXE, "--domain", std::to_string(domain)}, "/dev/null");
  auto observer = dds::make_participant("bench-observer", {domain, true, {}});
  const std::vector<std::string> twin{TWIN_EXE, "--domain", std::to_string(domain), "--quiet"};
  report("twin start", bench::twin_launches(observer, twin, rounds, false, "bench"));
  report("standby twin", bench::twin_launches(observer, twin, rounds, true, "bench"));
  station.stop();
  sim.stop();
}

// Hires the buffer "bench-buffer" as a twin hires it, for `rounds` gives and some to spare.
std::string hire_buffer(const dds::ParticipantPtr& participant, int rounds) {
  std::string why;
  const std::string award = test::hire(participant, "bench-buffer", "bench", "give", {"", "Part", rounds + 40}, &why);
  if (award.empty()) throw std::runtime_error("cannot hire bench-buffer: " + why);
  return award;
}

std::vector<double> buffer_round_trips(const dds::ParticipantPtr& participant, int rounds) {
  return round_trips(participant, dds::command_topic("bench-buffer"), "cell/command_events", "bench-buffer", rounds,
                     hire_buffer(participant, rounds));
}

// The round trips while a cell assembles 10 orders on the same host (the bench's echo and
// buffer on a domain of their own, the cell on another). A bare round and a command's round
// take turns, so that both meet the same load: the orders' work changes as they go on.
void under_load(const char* self, int domain, int rounds) {
  std::vector<std::string> args{CELLCTL_EXE, "run", "--domain", std::to_string(domain + 2)};
  for (int i = 0; i < 10; ++i) {
    args.push_back(std::string(PRODUCTS_DIR) + (i % 2 == 0 ? "/lego-tower/lego-tower.aml" : "/cranfield/cranfield.aml"));
  }
  args.insert(args.end(), {"--out", "/tmp/bench-cell-load"});
  auto participant = dds::make_participant("bench", {domain, true, {}});
  test::ChildProcess echo_side({self, "--echo", std::to_string(domain)});
  test::ChildProcess buffer({BUFFER_EXE, "--id", "bench-buffer", "--domain", std::to_string(domain), "--stock",
                             "Part=1000000"});
  const std::string award = hire_buffer(participant, rounds);
  bench::RoundTrips bare(participant, participant, "bench/ping", "bench/pong");
  bench::RoundTrips to_buffer(participant, participant, dds::command_topic("bench-buffer"), "cell/command_events");
  test::ChildProcess cell(args, "/tmp/bench-cell-load.log");
  std::this_thread::sleep_for(3s);  // the cell is up and the twins plan and assemble virtually
  std::vector<double> bare_us, command_us;
  for (int i = 0; i < rounds; ++i) {
    bare_us.push_back(bare.once(command("echo", "", i)));
    command_us.push_back(to_buffer.once(command("bench-buffer", award, i)));
  }
  report("while 10 orders run: bare Fast DDS ping-pong", bare_us);
  report("while 10 orders run: command to SUCCEEDED, buffer process", command_us);
  const int code = cell.wait_for_exit(std::chrono::minutes(5));
  std::cout << "  (the 10 orders' cellctl run ended with exit " << code << ")" << std::endl;
  buffer.stop();
  echo_side.stop();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::strcmp(argv[1], "--echo") == 0) return echo(std::stoi(argv[2]));
  int rounds = 1000, launches = 100;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--rounds") == 0) rounds = std::stoi(argv[i + 1]);
    if (std::strcmp(argv[i], "--launches") == 0) launches = std::stoi(argv[i + 1]);
  }
  test::clean_stale_dds_segments();
  const int domain = 199;
  try {
    auto participant = dds::make_participant("bench", {domain, true, {}});
    {
      test::ChildProcess echo_side({argv[0], "--echo", std::to_string(domain)});
      report("bare Fast DDS ping-pong, two processes", round_trips(participant, "bench/ping", "bench/pong", "echo", rounds));
      echo_side.stop();
    }
    {
      test::ChildProcess buffer({BUFFER_EXE, "--id", "bench-buffer", "--domain", std::to_string(domain), "--stock",
                                 "Part=1000000"});
      report("command to SUCCEEDED, buffer process", buffer_round_trips(participant, rounds));
      buffer.stop();
    }
    twin_start(domain + 1, launches);
    participant.reset();
    under_load(argv[0], domain + 3, rounds / 2);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
