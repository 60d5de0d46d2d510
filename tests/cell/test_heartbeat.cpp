// The supervisor of cellctl up ends and restarts a process whose heartbeat stops (its DDS
// participant may look alive while its loop is stuck), and one whose resource is not heard
// on DDS; it leaves alone one that beats and one that never beat (a discovery server knows
// nothing of heartbeats).

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>

#include "deploy/cellctl/supervisor.hpp"

namespace {

struct Event {
  std::string process, event, message;
};

bool has(const std::vector<Event>& events, const std::string& process, const std::string& event) {
  for (const auto& e : events) {
    if (e.process == process && e.event == event) return true;
  }
  return false;
}

}  // namespace

TEST_CASE("a process whose heartbeat stops, or whose resource is not heard, is ended and started again, and one that beats "
          "or never did runs on",
          "[process][supervision]") {
  using namespace std::chrono_literals;
  std::vector<Event> events;
  cellctl::Supervisor supervisor({{"stuck", {STUCK_LOOP_EXE, "1"}, false, {}},
                                  {"steady", {STUCK_LOOP_EXE, "1000"}, false, {}},
                                  {"silent", {STUCK_LOOP_EXE, "0"}, false, {}},
                                  {"ghost", {STUCK_LOOP_EXE, "1000"}, false, {"ghost-resource"}}},
                                 cellctl::RestartPolicy{},
                                 [&events](const std::string& process, const std::string& event, const std::string& what) {
                                   events.push_back({process, event, what});
                                 });
  const auto silence = 2s;
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (!(has(events, "stuck", "restarted") && has(events, "ghost", "restarted")) &&
         std::chrono::steady_clock::now() < deadline) {
    supervisor.end_unheard({}, silence);  // no resource heard on DDS
    REQUIRE(supervisor.tend().empty());
    std::this_thread::sleep_for(100ms);
  }
  std::string said;
  for (const auto& e : events) said += e.process + " " + e.event + ": " + e.message + "\n";
  INFO(said);
  REQUIRE(has(events, "stuck", "unheard"));
  CHECK(has(events, "stuck", "restarted"));
  CHECK(said.find("stuck runs but its heartbeat stopped") != std::string::npos);
  // It beats, but what it publishes is not heard.
  CHECK(has(events, "ghost", "restarted"));
  CHECK(said.find("ghost runs but has not been heard on DDS") != std::string::npos);
  // Beside it, the steady one beat all along, and the silent one never did.
  CHECK_FALSE(has(events, "steady", "unheard"));
  CHECK_FALSE(has(events, "silent", "unheard"));
  CHECK_FALSE(has(events, "steady", "ended"));
  CHECK_FALSE(has(events, "silent", "ended"));
}
