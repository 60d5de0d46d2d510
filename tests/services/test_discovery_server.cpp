// The cell's discovery server under a crowd: clients arriving by the dozen while it
// announces itself. Fast DDS 2.9.1 aborted a server that announced itself to a client it had
// not yet made a sender for (services/dds/participant.cpp says how the server avoids it).
// Announcing every millisecond instead of every half second makes that moment likely: on 2
// cores beside a CPU hog, 3 servers of 6 aborted without the fix.

#include <catch2/catch.hpp>

#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include "cell_idl/simulationPubSubTypes.h"
#include "services/dds/endpoints.hpp"
#include "services/dds/participant.hpp"
#include "tests/support/child_process.hpp"
#include "tests/support/domains.hpp"
#include "tests/support/sanitizers.hpp"

namespace domains = test::domains;

namespace {

using namespace std::chrono_literals;
using Probe = cell::Clock;

dds::ParticipantSettings settings(int serve) {
  dds::ParticipantSettings s;
  s.domain_id = domains::kDiscoveryServer;
  s.discovery.servers = {"127.0.0.1:21170"};
  s.discovery.serve = serve;
  if (serve >= 0) s.discovery.announce_every_s = 0.001;
  return s;
}

// A client that reads the probe topic until it is stopped.
int listener() {
  const auto participant = dds::make_participant("listener", settings(-1));
  dds::Reader<Probe, cell::ClockPubSubType> reader(participant, "test/probe", dds::TopicKind::state, [](const Probe&) {});
  for (;;) std::this_thread::sleep_for(1s);
}

// A client that writes the probe topic: 0 if it matched the listener (which it can only
// learn of through the server) within 60 s, else 1.
int prober(int wave) {
  const auto participant = dds::make_participant("prober-" + std::to_string(wave), settings(-1));
  dds::Writer<Probe, cell::ClockPubSubType> writer(participant, "test/probe", dds::TopicKind::state);
  return writer.wait_for_readers(1, 60s) ? 0 : 1;
}

// One of the crowd: a client that announces itself to the server and leaves a second later.
int newcomer(int i) {
  const auto participant = dds::make_participant("newcomer-" + std::to_string(i), settings(-1));
  std::this_thread::sleep_for(1s);
  return 0;
}

}  // namespace

TEST_CASE("discovery server: outlives newcomers that arrive by the dozen while it announces itself every millisecond",
          "[process][dds]") {
  test::clean_stale_dds_segments();
  // Before any thread of this process: the children are forks of it.
  test::ChildProcess server([] {
    const auto participant = dds::make_participant("discovery-0", settings(0));
    for (;;) std::this_thread::sleep_for(1s);
    return 0;
  });
  test::ChildProcess reader(listener);
  const int waves = 3, per_wave = test::kUnderSanitizers ? 12 : 60;
  for (int wave = 0; wave < waves; ++wave) {
    std::vector<std::unique_ptr<test::ChildProcess>> crowd;
    for (int i = 0; i < per_wave; ++i) {
      crowd.push_back(std::make_unique<test::ChildProcess>([=] { return newcomer(wave * per_wave + i); }));
    }
    test::ChildProcess probe([=] { return prober(wave); });
    INFO("wave " << wave);
    CHECK(probe.wait_for_exit(90s) == 0);
    for (auto& c : crowd) CHECK(c->wait_for_exit(90s) == 0);
    REQUIRE(server.running());
  }
  CHECK(reader.running());
}
