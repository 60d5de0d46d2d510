// Benchmark of DDS discovery on one host: simple discovery (every participant announces
// itself to a fixed range of ports) against the cell's discovery server. N participants as in
// a cell: one observer (as cellctl and the resources are) writes "capability" and reads
// "status"; the N-1 others (as twins are) write status and read the capability. Then a
// newcomer joins five times (as a twin does).
//  - settle: until the observer's capability writer matched the readers of all N-1 others;
//  - steady traffic: loopback bytes and packets per second with nobody joining;
//  - join: from creating the newcomer until the observer reads its status and it reads the
//    capability, p50 and max over the rounds; the loopback bytes and packets it cost beyond
//    the steady traffic (p50).
// Loopback counters are the host's (/proc/net/dev): run it on a quiet machine.
// Run: build/release/bin/bench_discovery --participants 60 --mode server [--domain 205]

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cell_idl/simulationPubSubTypes.h"
#include "services/dds/endpoints.hpp"
#include "services/dds/participant.hpp"
#include "services/node/run.hpp"
#include "tests/bench/bench_support.hpp"
#include "tests/support/child_process.hpp"

namespace {

using Steady = std::chrono::steady_clock;
constexpr int kPerHost = 10;  // participants per helper process

using ClockWriter = dds::Writer<cell::Clock, cell::ClockPubSubType>;
using ClockReader = dds::Reader<cell::Clock, cell::ClockPubSubType>;

struct Member {
  dds::ParticipantPtr participant;
  std::unique_ptr<ClockWriter> writer;
  std::unique_ptr<ClockReader> reader;
};

// The observer writes the capability and reads the status; the others the other way round.
Member join(const std::string& name, const dds::ParticipantSettings& settings, bool observer) {
  Member m;
  m.participant = dds::make_participant(name, settings);
  m.writer = std::make_unique<ClockWriter>(m.participant, observer ? "bench/capability" : "bench/status", dds::TopicKind::state);
  m.reader = std::make_unique<ClockReader>(m.participant, observer ? "bench/status" : "bench/capability",
                                           dds::TopicKind::state, [](const cell::Clock&) {});
  return m;
}

struct Loopback {
  double bytes = 0, packets = 0;
};

Loopback loopback() {
  std::ifstream dev("/proc/net/dev");
  for (std::string line; std::getline(dev, line);) {
    const auto colon = line.find(':');
    if (colon == std::string::npos || line.substr(0, colon).find("lo") == std::string::npos ||
        line.substr(0, colon).find_first_not_of(" lo") != std::string::npos) {
      continue;
    }
    std::istringstream fields(line.substr(colon + 1));
    Loopback l;
    fields >> l.bytes >> l.packets;  // received = sent on loopback
    return l;
  }
  return {};
}

std::atomic<bool> running{true};
void stop(int) { running = false; }

}  // namespace

int main(int argc, char** argv) {
  int participants = 20, domain = 205, host = 0;
  std::string mode = "server";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--participants") participants = std::stoi(argv[i + 1]);
    if (key == "--mode") mode = argv[i + 1];
    if (key == "--domain") domain = std::stoi(argv[i + 1]);
    if (key == "--host") host = std::stoi(argv[i + 1]);  // a helper process: this many participants
  }
  dds::ParticipantSettings settings;
  settings.domain_id = domain;
  const std::string server = "127.0.0.1:" + std::to_string(11811 + domain);
  if (mode == "server") settings.discovery.servers = {server};

  if (host > 0) {  // a helper: `host` participants until killed
    std::signal(SIGTERM, stop);
    services::stop_with_parent();
    std::vector<Member> members;
    for (int i = 0; i < host; ++i) members.push_back(join("member", settings, false));
    while (running) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    std::_Exit(0);  // ten participants' teardown is not measured
  }

  std::vector<std::unique_ptr<test::ChildProcess>> children;
  if (mode == "server") {
    children.push_back(std::make_unique<test::ChildProcess>(
        std::vector<std::string>{DISCOVERY_SERVER_EXE, "--domain", std::to_string(domain), "--discovery-server", server,
                                 "--serve", "0"},
        "/dev/null"));
  }
  for (int left = participants - 1; left > 0; left -= kPerHost) {
    children.push_back(std::make_unique<test::ChildProcess>(
        std::vector<std::string>{argv[0], "--host", std::to_string(std::min(left, kPerHost)), "--mode", mode, "--domain",
                                 std::to_string(domain)},
        "/tmp/bench-discovery-host-" + std::to_string(left) + ".log"));
  }
  const auto started = Steady::now();
  Member observer = join("observer", settings, true);
  const bool settled = observer.writer->wait_for_readers(participants - 1, std::chrono::seconds(90));
  const double settle_s = std::chrono::duration<double>(Steady::now() - started).count();
  const int found = observer.writer->wait_for_settled_readers(std::chrono::seconds(2), std::chrono::seconds(5));

  const Loopback s0 = loopback();
  const auto steady_start = Steady::now();
  std::this_thread::sleep_for(std::chrono::seconds(5));
  const Loopback s1 = loopback();
  const double steady_s = std::chrono::duration<double>(Steady::now() - steady_start).count();
  const double bytes_per_s = (s1.bytes - s0.bytes) / steady_s, packets_per_s = (s1.packets - s0.packets) / steady_s;

  std::vector<double> joins_ms, join_bytes, join_packets;
  int joined = 0;
  for (int round = 0; round < 5; ++round) {
    const Loopback c0 = loopback();
    const auto t0 = Steady::now();
    {
      Member twin = join("twin", settings, false);
      const bool all = twin.writer->wait_for_readers(1, std::chrono::seconds(30)) &&
                       observer.writer->wait_for_readers(participants, std::chrono::seconds(30));
      joins_ms.push_back(std::chrono::duration<double, std::milli>(Steady::now() - t0).count());
      joined += all ? 1 : 0;
      std::this_thread::sleep_for(std::chrono::seconds(1));  // the announcements after the match
      const Loopback c1 = loopback();
      const double elapsed = std::chrono::duration<double>(Steady::now() - t0).count();
      join_bytes.push_back(c1.bytes - c0.bytes - bytes_per_s * elapsed);
      join_packets.push_back(c1.packets - c0.packets - packets_per_s * elapsed);
    }
    std::this_thread::sleep_for(std::chrono::seconds(2));  // the others forget it
  }
  std::cout << mode << " discovery, " << participants << " participants: settled " << (settled ? "in " : "not in ")
            << settle_s << " s (observer matched " << found << " of " << participants - 1 << " readers); steady "
            << bytes_per_s / 1000 << " kB/s, " << packets_per_s << " packets/s on loopback; join (" << joined
            << " of 5 matched) p50 " << bench::percentile(joins_ms, 0.5) << " ms, max "
            << bench::percentile(joins_ms, 1.0) << " ms, " << bench::percentile(join_bytes, 0.5) / 1000 << " kB and "
            << bench::percentile(join_packets, 0.5) << " packets per join (p50)" << std::endl;
  return settled && joined == 5 ? 0 : 1;
}
