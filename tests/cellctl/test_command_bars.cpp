// The Gantt chart's bars from command events (deploy/cellctl/command_bars.hpp): when a command
// starts, that a queued one starts at its first EXECUTING, that one that never ran makes no
// bar, and that a process's end ends its commands.

#include <catch2/catch.hpp>

#include "deploy/cellctl/command_bars.hpp"

namespace {

cellctl::CommandHeard event(const std::string& command, const std::string& resource, cell::CommandState state, double t) {
  cellctl::CommandHeard e;
  e.command = command;
  e.resource = resource;
  e.order = "order-1";
  e.operation = "translate";
  e.state = state;
  e.sim_time = t;
  return e;
}

}  // namespace

TEST_CASE("a command's bar runs from its start to its end, and a queued one starts when it leaves the queue",
          "[cellctl][dashboard]") {
  cellctl::CommandBars bars;
  CHECK_FALSE(bars.take(event("c1", "arm-1", cell::ACCEPTED, 1.0)));
  CHECK_FALSE(bars.take(event("c2", "arm-1", cell::ACCEPTED, 1.5)));  // queued behind c1
  REQUIRE(bars.under_way().count("arm-1"));
  CHECK(bars.under_way().at("arm-1").since == 1.0);
  CHECK_FALSE(bars.take(event("c1", "arm-1", cell::EXECUTING, 2.0)));  // progress: c1 began at 1.0

  const auto first = bars.take(event("c1", "arm-1", cell::SUCCEEDED, 4.0));
  REQUIRE(first);
  CHECK(first->start == 1.0);
  CHECK(first->end == 4.0);
  CHECK_FALSE(bars.under_way().count("arm-1"));  // c2 has not started yet

  CHECK_FALSE(bars.take(event("c2", "arm-1", cell::EXECUTING, 4.0)));
  CHECK(bars.under_way().at("arm-1").since == 4.0);
  const auto second = bars.take(event("c2", "arm-1", cell::ABORTED, 5.0));
  REQUIRE(second);
  CHECK(second->start == 4.0);
  CHECK(second->state == cell::ABORTED);
}

TEST_CASE("a command that never ran makes no bar, and a resource's lost process ends its commands", "[cellctl][dashboard]") {
  cellctl::CommandBars bars;
  CHECK_FALSE(bars.take(event("r1", "buffer-1", cell::REJECTED, 1.0)));  // never accepted

  bars.take(event("c1", "arm-1", cell::ACCEPTED, 1.0));
  bars.take(event("c2", "arm-1", cell::ACCEPTED, 1.0));
  CHECK_FALSE(bars.take(event("c2", "arm-1", cell::CANCELED, 2.0)));  // canceled in the queue

  bars.take(event("f1", "mobile-robot-1", cell::ACCEPTED, 1.0));
  bars.lose([](const std::string& resource) { return resource == "arm-1"; });
  CHECK_FALSE(bars.under_way().count("arm-1"));
  CHECK(bars.under_way().count("mobile-robot-1"));
  CHECK_FALSE(bars.take(event("c1", "arm-1", cell::SUCCEEDED, 3.0)));  // a late end of a lost command
}
