// The function-block runtime, driven with events and no DDS.

#include <thread>

#include <catch2/catch.hpp>

#include "services/blocks/command_lifecycle.hpp"
#include "services/blocks/contractor.hpp"
#include "services/node/run.hpp"
#include "services/runtime/block_test_fixture.hpp"

namespace {

// Counts REQ events and answers each with CNF carrying the running count.
class Counter : public fb::BasicBlock {
 public:
  explicit Counter(std::string name) : fb::BasicBlock(std::move(name), "READY") {
    declare_input("REQ", {"step"});
    declare_output("CNF", {"count"});
    transition("READY", "REQ", "READY", [this](const fb::Data& d) {
      count += d.count("step") ? fb::get<std::int64_t>(d, "step") : 1;
      emit("CNF", {{"count", count}});
    }, [](const fb::Data& d) { return !d.count("step") || fb::get<std::int64_t>(d, "step") > 0; });
  }
  std::int64_t count = 0;
};

// A chart with enum states: GO starts a job; the action finds it done and raises DONE,
// which the chart takes once the action is over, by a transition of its own.
enum class Job { idle, working, done };
class Worker : public fb::BasicChart<Job> {
 public:
  explicit Worker(std::string name) : BasicChart(std::move(name), Job::idle) {
    declare_input("GO");
    declare_output("STARTED");
    declare_output("FINISHED");
    transition(Job::idle, "GO", Job::working, [this](const fb::Data&) {
      raise("DONE");
      seen_in_action = state();  // not yet changed by what it raised
      emit("STARTED");
    });
    transition(Job::working, "DONE", Job::done, [this](const fb::Data&) { emit("FINISHED"); });
  }
  Job seen_in_action = Job::idle;
};

using Names = std::vector<std::string>;
}  // namespace

TEST_CASE("a resource delivers events along its connections, one at a time, in order", "[fb]") {
  fb::Resource resource("r", 16);
  auto& a = resource.add(std::make_unique<Counter>("a"));
  auto& b = resource.add(std::make_unique<Counter>("b"));
  auto& c = resource.add(std::make_unique<Counter>("c"));
  resource.connect("a", "CNF", "b", "REQ");
  resource.connect("a", "CNF", "c", "REQ");  // one output, two inputs
  resource.post("a", "REQ");
  resource.post("a", "REQ");
  CHECK(resource.run_until_idle() == 6);
  CHECK(a.count == 2);
  CHECK(b.count == 2);
  CHECK(c.count == 2);
}

TEST_CASE("a process's own event for a full queue waits for room, after what came first", "[fb]") {
  fb::Resource resource("station", 2);
  auto& a = resource.add(std::make_unique<Counter>("a"));
  auto& init = resource.add(std::make_unique<Counter>("init"));
  resource.post("a", "REQ");
  resource.post("a", "REQ");
  services::post_when_room(resource, "init", "REQ");
  CHECK(a.count == 1);  // one delivered to make room
  CHECK(init.count == 0);
  CHECK(resource.run_until_idle() == 2);
  CHECK(a.count == 2);
  CHECK(init.count == 1);
}

TEST_CASE("a full event queue refuses loudly and counts what it refused", "[fb]") {
  fb::Resource resource("station", 2);
  auto& a = resource.add(std::make_unique<Counter>("a"));
  resource.post("a", "REQ");
  resource.post("a", "REQ");
  CHECK_THROWS_MATCHES(resource.post("a", "REQ"), fb::EventQueueOverflow,
                       Catch::Matchers::Message("event queue of resource station is full (2 events): refused a.REQ"));
  CHECK(resource.refused() == 1);
  CHECK(resource.run_until_idle() == 2);
  CHECK(a.count == 2);
  // Events a block emits are never refused: they follow from an event already taken, and a
  // refusal would throw out of the resource's thread. The next event from outside waits.
  fb::Resource tight("tight", 1);
  auto& y = tight.add(std::make_unique<Counter>("y"));
  auto& z = tight.add(std::make_unique<Counter>("z"));
  tight.add(std::make_unique<Counter>("x"));
  tight.connect("x", "CNF", "y", "REQ");
  tight.connect("x", "CNF", "z", "REQ");
  tight.post("x", "REQ");
  CHECK_NOTHROW(tight.run_one());
  CHECK_THROWS_AS(tight.post("x", "REQ"), fb::EventQueueOverflow);
  CHECK(tight.run_until_idle() == 2);
  CHECK(y.count == 1);
  CHECK(z.count == 1);
  CHECK(tight.refused() == 1);
}

TEST_CASE("wiring mistakes are errors at once", "[fb]") {
  fb::Resource resource("r", 4);
  resource.add(std::make_unique<Counter>("a"));
  CHECK_THROWS_AS(resource.connect("a", "NOPE", "a", "REQ"), std::logic_error);
  CHECK_THROWS_AS(resource.connect("a", "CNF", "a", "NOPE"), std::logic_error);
  CHECK_THROWS_AS(resource.connect("a", "CNF", "ghost", "REQ"), std::logic_error);
  CHECK_THROWS_AS(resource.post("a", "CNF"), std::logic_error);
  CHECK_THROWS_AS(resource.add(std::make_unique<Counter>("a")), std::logic_error);
}

TEST_CASE("an ECC fires the first transition whose event and guard match", "[fb]") {
  fb::BlockTestFixture<Counter> fixture("counter");
  CHECK(fb::event_names(fixture.send("REQ", {{"step", std::int64_t{5}}})) == Names{"CNF"});
  CHECK(fixture.block().count == 5);
  CHECK(fixture.send("REQ", {{"step", std::int64_t{-1}}}).empty());  // guard false: consumed
  CHECK(fixture.block().unhandled_events() == 1);
  const auto out = fixture.send("REQ");
  REQUIRE(out.size() == 1);
  CHECK(fb::get<std::int64_t>(out[0].data, "count") == 6);
}

TEST_CASE("command life cycle: accepted, executing, succeeded", "[fb][lifecycle]") {
  fb::BlockTestFixture<fb::CommandLifecycle> f("lifecycle");
  const auto accepted = f.send("COMMAND", {{"command_id", std::string("c1")}});
  CHECK(fb::event_names(accepted) == Names{"ACCEPTED", "START"});
  CHECK(fb::get<std::string>(accepted[0].data, "command_id") == "c1");
  const auto progress = f.send("PROGRESS", {{"progress", 0.5}});
  REQUIRE(fb::event_names(progress) == Names{"EXECUTING"});
  CHECK(fb::get<double>(progress[0].data, "progress") == 0.5);
  CHECK(fb::event_names(f.send("DONE")) == Names{"SUCCEEDED", "IDLE"});
  CHECK(f.block().state() == "IDLE");
}

TEST_CASE("command life cycle: one command at a time, and failures carry their reason", "[fb][lifecycle]") {
  fb::BlockTestFixture<fb::CommandLifecycle> f("lifecycle");
  f.send("COMMAND", {{"command_id", std::string("c1")}});
  const auto busy = f.send("COMMAND", {{"command_id", std::string("c2")}});
  REQUIRE(fb::event_names(busy) == Names{"REJECTED"});
  CHECK(fb::get<std::string>(busy[0].data, "command_id") == "c2");
  CHECK(fb::get<std::string>(busy[0].data, "reason") == "busy with c1");
  const auto aborted = f.send("FAIL", {{"reason", std::string("collision with B6")}});
  REQUIRE(fb::event_names(aborted) == Names{"ABORTED", "IDLE"});
  CHECK(fb::get<std::string>(aborted[0].data, "reason") == "collision with B6");
  CHECK(fb::event_names(f.send("COMMAND", {{"command_id", std::string("c2")}})) ==
        Names{"ACCEPTED", "START"});
}

TEST_CASE("command life cycle: cancel, and a device that finishes before it can stop", "[fb][lifecycle]") {
  fb::BlockTestFixture<fb::CommandLifecycle> f("lifecycle");
  f.send("COMMAND", {{"command_id", std::string("c1")}});
  CHECK(f.send("CANCEL", {{"command_id", std::string("other")}}).empty());  // not ours: ignored
  CHECK(fb::event_names(f.send("CANCEL", {{"command_id", std::string("c1")}})) ==
        Names{"CANCELING", "STOP"});
  CHECK(fb::event_names(f.send("STOPPED")) == Names{"CANCELED", "IDLE"});

  f.send("COMMAND", {{"command_id", std::string("c2")}});
  f.send("CANCEL", {{"command_id", std::string("c2")}});
  CHECK(fb::event_names(f.send("DONE")) == Names{"SUCCEEDED", "IDLE"});
  CHECK(f.block().state() == "IDLE");
}

TEST_CASE("events posted from another thread arrive in order", "[fb][threads]") {
  fb::Resource resource("r", 2048);
  auto& a = resource.add(std::make_unique<Counter>("a"));
  std::thread producer([&] {
    for (std::int64_t i = 1; i <= 1000; ++i) resource.post("a", "REQ", {{"step", i}});
  });
  std::size_t delivered = 0;
  while (delivered < 1000 && resource.wait_and_run_one(std::chrono::seconds(5))) ++delivered;
  producer.join();
  CHECK(delivered == 1000);
  CHECK(a.count == 1000 * 1001 / 2);
}

TEST_CASE("command life cycle with a queue: one executes, the rest wait their turn in order", "[fb][lifecycle]") {
  fb::BlockTestFixture<fb::CommandLifecycle> f("lifecycle", fb::CommandLifecycle::WhenBusy::queue);
  f.send("COMMAND", {{"command_id", std::string("c1")}});
  CHECK(fb::event_names(f.send("COMMAND", {{"command_id", std::string("c2")}})) == Names{"ACCEPTED"});
  f.send("COMMAND", {{"command_id", std::string("c3")}});
  CHECK(f.block().queued() == 2);
  const auto done = f.send("DONE", {{"distance", 1.5}});
  REQUIRE(fb::event_names(done) == Names{"SUCCEEDED", "EXECUTING", "START"});
  CHECK(fb::get<std::string>(done[0].data, "command_id") == "c1");
  CHECK(fb::get<double>(done[0].data, "distance") == 1.5);  // the device's data goes along
  CHECK(fb::get<std::string>(done[1].data, "command_id") == "c2");
  const auto failed = f.send("FAIL", {{"reason", std::string("buffer-1 has no Peg")}});
  REQUIRE(fb::event_names(failed) == Names{"ABORTED", "EXECUTING", "START"});
  CHECK(fb::get<std::string>(failed[1].data, "command_id") == "c3");
  CHECK(fb::event_names(f.send("DONE")) == Names{"SUCCEEDED", "IDLE"});
  CHECK(f.block().state() == "IDLE");
}

TEST_CASE("command life cycle with a queue: a queued command is canceled at once", "[fb][lifecycle]") {
  fb::BlockTestFixture<fb::CommandLifecycle> f("lifecycle", fb::CommandLifecycle::WhenBusy::queue);
  f.send("COMMAND", {{"command_id", std::string("c1")}});
  f.send("COMMAND", {{"command_id", std::string("c2")}});
  f.send("COMMAND", {{"command_id", std::string("c3")}});
  const auto canceled = f.send("CANCEL", {{"command_id", std::string("c2")}});
  REQUIRE(fb::event_names(canceled) == Names{"CANCELED"});
  CHECK(fb::get<std::string>(canceled[0].data, "command_id") == "c2");
  const auto next = f.send("DONE");
  REQUIRE(fb::event_names(next) == Names{"SUCCEEDED", "EXECUTING", "START"});
  CHECK(fb::get<std::string>(next[1].data, "command_id") == "c3");  // c2 is gone
}

TEST_CASE("command life cycle: a cancel counts only from the command's own order", "[fb][lifecycle]") {
  fb::BlockTestFixture<fb::CommandLifecycle> f("lifecycle", fb::CommandLifecycle::WhenBusy::queue);
  const auto command = [&](const char* id, const char* order) {
    f.send("COMMAND", {{"command_id", std::string(id)}, {"order_id", std::string(order)}});
  };
  const auto cancel = [&](const char* id, const char* order) {
    return fb::event_names(f.send("CANCEL", {{"command_id", std::string(id)}, {"order_id", std::string(order)}}));
  };
  command("c1", "o1");
  command("c2", "o1");
  CHECK(cancel("c1", "o2").empty());  // executing, another order's
  CHECK(cancel("c2", "o2").empty());  // queued, another order's
  CHECK(cancel("c2", "").empty());
  CHECK(f.block().queued() == 1);
  CHECK(cancel("c2", "o1") == Names{"CANCELED"});
  CHECK(cancel("c1", "o1") == Names{"CANCELING", "STOP"});
  CHECK(fb::event_names(f.send("STOPPED")) == Names{"CANCELED", "IDLE"});
  CHECK(cancel("c1", "o1").empty());  // ended: nothing to cancel
}

TEST_CASE("a chart's internal event is taken by a transition once the action that raised it is over", "[fb]") {
  fb::BlockTestFixture<Worker> f("worker");
  const auto out = f.send("GO");
  CHECK(fb::event_names(out) == Names{"STARTED", "FINISHED"});
  CHECK(f.block().seen_in_action == Job::working);
  CHECK(f.block().state() == Job::done);
  CHECK(f.block().unhandled_events() == 0);
  f.send("GO");  // no transition from done
  CHECK(f.block().unhandled_events() == 1);
}
