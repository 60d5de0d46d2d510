// Publish/subscribe service blocks over Fast DDS, two participants in one process. Each test
// case has a domain id of its own, participants are localhost-only, and every wait is
// bounded.

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

#include <catch2/catch.hpp>
#include <fastrtps/xmlparser/XMLProfileManager.h>

#include "capabilitiesPubSubTypes.h"
#include "commandsPubSubTypes.h"
#include "simulationPubSubTypes.h"
#include "services/dds/service_blocks.hpp"
#include "services/runtime/block_test_fixture.hpp"
#include "tests/support/domains.hpp"

namespace domains = test::domains;

namespace {

using EventPublisher = dds::PublishBlock<cell::CommandEvent, cell::CommandEventPubSubType>;
using EventSubscriber = dds::SubscribeBlock<cell::CommandEvent, cell::CommandEventPubSubType>;
using CapabilityWriter = dds::Writer<cell::Capability, cell::CapabilityPubSubType>;
using CapabilitySubscriber = dds::SubscribeBlock<cell::Capability, cell::CapabilityPubSubType>;

cell::CommandEvent to_event(const fb::Data& d) {
  cell::CommandEvent e;
  e.command_id(fb::get<std::string>(d, "command_id"));
  e.resource_id("station");
  e.state(cell::SUCCEEDED);
  e.sim_time(fb::get<double>(d, "t"));
  return e;
}

fb::Data from_event(const cell::CommandEvent& e) {
  return {{"command_id", e.command_id().to_string()}, {"done", e.state() == cell::SUCCEEDED}, {"t", e.sim_time()}};
}

// Runs the resource until the recorder holds `count` events or 10 s pass.
bool run_until(fb::Resource& resource, const fb::EventRecorder& recorder, std::size_t count) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (recorder.events.size() < count && std::chrono::steady_clock::now() < deadline) {
    resource.wait_and_run_one(std::chrono::milliseconds(100));
  }
  return recorder.events.size() >= count;
}

}  // namespace

TEST_CASE("an event published by one block arrives at a subscribing block", "[dds]") {
  const dds::ParticipantSettings settings{domains::kDdsEvents, true, {}};
  auto twin = dds::make_participant("test-twin", settings);
  auto station = dds::make_participant("test-station", settings);

  fb::Resource resource("r", 64);
  auto& pub = resource.add(std::make_unique<EventPublisher>("pub", station, "cell/command_events",
                                                            dds::TopicKind::events, to_event));
  auto& sub = resource.add(std::make_unique<EventSubscriber>("sub", twin, "cell/command_events",
                                                             dds::TopicKind::events, from_event));
  auto& recorder = resource.add(std::make_unique<fb::EventRecorder>(sub));
  resource.connect("sub", "IND", "recorder", "IND");
  sub.start();
  REQUIRE(pub.writer().wait_for_readers(1, std::chrono::seconds(10)));

  resource.post("pub", "REQ", {{"command_id", std::string("c-1")}, {"t", 12.5}});
  REQUIRE(run_until(resource, recorder, 1));
  const fb::Data& got = recorder.events[0].data;
  CHECK(fb::get<std::string>(got, "command_id") == "c-1");
  CHECK(fb::get<bool>(got, "done"));
  CHECK(fb::get<double>(got, "t") == 12.5);
}

TEST_CASE("state topics: a late reader sees the last state, and a dead writer is noticed", "[dds]") {
  const dds::ParticipantSettings settings{domains::kDdsStateTopics, true, {}};
  auto twin = dds::make_participant("test-twin", settings);
  auto buffer = dds::make_participant("test-buffer", settings);
  dds::QosSettings quick;
  quick.liveliness_lease_s = 0.5;
  auto writer = std::make_unique<CapabilityWriter>(buffer, "cell/capabilities", dds::TopicKind::state, quick);
  cell::Capability capability;
  capability.resource_id("buffer-1");
  capability.kind("buffer");
  capability.stock().push_back(cell::PartStock());
  capability.stock()[0].part_type("SquarePeg");
  capability.stock()[0].count(2);
  REQUIRE(writer->write(capability));  // before any reader exists

  fb::Resource resource("r", 64);
  auto& sub = resource.add(std::make_unique<CapabilitySubscriber>(
      "capabilities", twin, "cell/capabilities", dds::TopicKind::state, [](const cell::Capability& c) {
        return fb::Data{{"resource_id", c.resource_id().to_string()},
                        {"stock", c.stock().empty() ? std::int64_t{0} : std::int64_t{c.stock()[0].count()}}};
      }));
  auto& recorder = resource.add(std::make_unique<fb::EventRecorder>(sub));
  resource.connect("capabilities", "IND", "recorder", "IND");
  resource.connect("capabilities", "GONE", "recorder", "GONE");
  sub.start();
  REQUIRE(run_until(resource, recorder, 1));
  CHECK(recorder.events[0].name == "IND");
  CHECK(fb::get<std::string>(recorder.events[0].data, "resource_id") == "buffer-1");
  CHECK(fb::get<std::int64_t>(recorder.events[0].data, "stock") == 2);

  // The buffer process dies: its participant goes away, its capability with it.
  writer.reset();
  buffer.reset();
  REQUIRE(run_until(resource, recorder, 2));
  CHECK(recorder.events[1].name == "GONE");
  CHECK(fb::get<std::string>(recorder.events[1].data, "resource_id") == "buffer-1");
}

// A reader reads an ended instance rather than take it (Reader::sweep_ended says why): its end
// must still be said once, however many samples of other instances come after; and a topic
// without a key (cell-sim's clock) has its end said too. A first version of the sweep read
// the keyless topic's one instance for ever: `cellctl up` never finished its teardown.
TEST_CASE("state topics: an end is said once while other states come, a keyless topic's too", "[dds]") {
  const dds::ParticipantSettings settings{domains::kDdsEndSaidOnce, true, {}};
  auto twin = dds::make_participant("test-twin", settings);
  auto buffers = dds::make_participant("test-buffers", settings);
  dds::QosSettings quick;
  quick.liveliness_lease_s = 0.5;
  std::mutex mutex;
  std::condition_variable changed;
  int heard = 0;
  std::vector<std::string> gone;
  const auto wait_until = [&](auto&& done) {
    std::unique_lock<std::mutex> lock(mutex);
    return changed.wait_for(lock, std::chrono::seconds(10), done);
  };
  {
    dds::Reader<cell::Capability, cell::CapabilityPubSubType> reader(
        twin, "cell/capabilities", dds::TopicKind::state,
        [&](const cell::Capability&) {
          std::lock_guard<std::mutex> lock(mutex);
          ++heard;
          changed.notify_all();
        },
        [&](const cell::Capability& c) {
          std::lock_guard<std::mutex> lock(mutex);
          gone.push_back(c.resource_id().to_string());
          changed.notify_all();
        },
        quick);
    auto leaving = std::make_unique<CapabilityWriter>(buffers, "cell/capabilities", dds::TopicKind::state, quick);
    CapabilityWriter staying(buffers, "cell/capabilities", dds::TopicKind::state, quick);
    cell::Capability capability;
    capability.resource_id("buffer-1");
    REQUIRE(leaving->write(capability));
    capability.resource_id("buffer-2");
    capability.queued_commands(0);
    REQUIRE(staying.write(capability));
    REQUIRE(wait_until([&] { return heard == 2; }));
    leaving.reset();
    REQUIRE(wait_until([&] { return !gone.empty(); }));
    for (int i = 1; i <= 20; ++i) {  // one at a time: a state reader keeps the last of each instance
      capability.queued_commands(i);
      REQUIRE(staying.write(capability));
      REQUIRE(wait_until([&] { return heard == 2 + i; }));
    }
    std::lock_guard<std::mutex> lock(mutex);
    CHECK(gone == std::vector<std::string>{"buffer-1"});
  }
  int clock_gone = 0;
  dds::Reader<cell::Clock, cell::ClockPubSubType> clocks(
      twin, "sim/clock", dds::TopicKind::state, [](const cell::Clock&) {},
      [&](const cell::Clock&) {
        std::lock_guard<std::mutex> lock(mutex);
        ++clock_gone;
        changed.notify_all();
      },
      quick);
  {
    dds::Writer<cell::Clock, cell::ClockPubSubType> clock(buffers, "sim/clock", dds::TopicKind::state, quick);
    REQUIRE(clock.wait_for_readers(1, std::chrono::seconds(10)));
    REQUIRE(clock.write(cell::Clock()));
    REQUIRE(clock.wait_for_acknowledgments(std::chrono::seconds(10)));
  }
  REQUIRE(wait_until([&] { return clock_gone > 0; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  std::lock_guard<std::mutex> lock(mutex);
  CHECK(clock_gone == 1);
}

// A state writer writes its last samples again at a third of its lease (so that a reader that
// took it for gone while it was starved has its state back, test_buffer_process.cpp): a reader
// delivers a state once, again only when it changes.
TEST_CASE("state topics: a state written again is delivered once, a changed one each time, an ended one again",
          "[dds]") {
  const dds::ParticipantSettings settings{domains::kDdsRepeatedState, true, {}};
  auto twin = dds::make_participant("test-twin", settings);
  auto buffer = dds::make_participant("test-buffer", settings);
  dds::QosSettings quick;
  quick.liveliness_lease_s = 0.3;  // written again every 0.1 s
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<int> seen;  // the stock of each capability delivered
  dds::Reader<cell::Capability, cell::CapabilityPubSubType> reader(
      twin, "cell/capabilities", dds::TopicKind::state,
      [&](const cell::Capability& c) {
        std::lock_guard<std::mutex> lock(mutex);
        seen.push_back(c.stock()[0].count());
        changed.notify_all();
      },
      {}, quick);
  const auto seen_after = [&](std::chrono::milliseconds wait, std::size_t count) {
    std::unique_lock<std::mutex> lock(mutex);
    changed.wait_for(lock, wait, [&] { return seen.size() >= count; });
    return seen;
  };
  CapabilityWriter writer(buffer, "cell/capabilities", dds::TopicKind::state, quick);
  cell::Capability capability;
  capability.resource_id("buffer-1");
  capability.kind("buffer");
  capability.stock().push_back(cell::PartStock());
  capability.stock()[0].part_type("SquarePeg");
  capability.stock()[0].count(2);
  REQUIRE(writer.wait_for_readers(1, std::chrono::seconds(10)));
  REQUIRE(writer.write(capability));
  REQUIRE(writer.write(capability));
  CHECK(seen_after(std::chrono::seconds(10), 1) == std::vector<int>{2});
  // Ten refreshes and more: nothing new is delivered.
  CHECK(seen_after(std::chrono::milliseconds(1000), 2) == std::vector<int>{2});
  capability.stock()[0].count(1);
  REQUIRE(writer.write(capability));
  CHECK(seen_after(std::chrono::seconds(10), 2) == std::vector<int>{2, 1});
  // An instance that ended (unregistered: an identity given back to the pool) and is written
  // again as it was is news (a twin's binding to the same order again).
  writer.unregister(capability);
  REQUIRE(writer.write(capability));
  CHECK(seen_after(std::chrono::seconds(10), 3) == std::vector<int>{2, 1, 1});
}

// An instance its writer unregisters (or disposes) has its end replace its last sample in a
// state reader: the end must still be said, with the sample last delivered, before the
// instance lives again. It was not: the same state written again came twice with no end
// between.
TEST_CASE("state topics: an instance unregistered and written again has its end said between", "[dds]") {
  const dds::ParticipantSettings settings{domains::kDdsMissedEnd, true, {}};
  auto twin = dds::make_participant("test-twin", settings);
  auto buffer = dds::make_participant("test-buffer", settings);
  dds::QosSettings quick;
  quick.liveliness_lease_s = 0.5;
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<std::string> said;  // "+id" for a state, "-id" for an end, in order
  const auto saying = [&](const char* sign) {
    return [&, sign](const cell::Capability& c) {
      std::lock_guard<std::mutex> lock(mutex);
      said.push_back(sign + c.resource_id().to_string());
      changed.notify_all();
    };
  };
  dds::Reader<cell::Capability, cell::CapabilityPubSubType> reader(twin, "cell/capabilities", dds::TopicKind::state,
                                                                   saying("+"), saying("-"), quick);
  CapabilityWriter writer(buffer, "cell/capabilities", dds::TopicKind::state, quick);
  REQUIRE(writer.wait_for_readers(1, std::chrono::seconds(10)));
  cell::Capability capability;
  capability.resource_id("buffer-1");
  REQUIRE(writer.write(capability));
  writer.unregister(capability);
  REQUIRE(writer.write(capability));
  std::unique_lock<std::mutex> lock(mutex);
  changed.wait_for(lock, std::chrono::seconds(10), [&] { return said.size() >= 3; });
  changed.wait_for(lock, std::chrono::milliseconds(300), [&] { return said.size() > 3; });  // nothing more comes
  CHECK(said == std::vector<std::string>{"+buffer-1", "-buffer-1", "+buffer-1"});
}

// A drain started by a data callback runs under the reader's lock: nothing arrives meanwhile.
// One started by a writer that left (or lapsed) does not, and an instance may end and live
// again during it: the comeback has no end to read, only its instance's generation, one above
// the sample last delivered. Here the reader is held in its callback for B's end (B's process
// died) while A's writer unregisters A and writes it again. (A lease of 30 s: no refresh, so
// no other drain, comes meanwhile.)
TEST_CASE("state topics: an instance that ends and lives again during a drain has its end said first", "[dds]") {
  const dds::ParticipantSettings settings{domains::kDdsEndInTheDrain, true, {}};
  auto twin = dds::make_participant("test-twin", settings);
  dds::QosSettings slow;
  slow.liveliness_lease_s = 30;
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<std::string> said;  // "+id" for a state, "-id" for an end, in order
  bool holding = false, released = false;
  const auto wait_until = [&](auto&& done) {
    std::unique_lock<std::mutex> lock(mutex);
    return changed.wait_for(lock, std::chrono::seconds(10), done);
  };
  const auto saying = [&](char sign) {
    return [&, sign](const cell::Capability& c) {
      std::unique_lock<std::mutex> lock(mutex);
      said.push_back(sign + c.resource_id().to_string());
      changed.notify_all();
      if (said.back() != "-B") return;
      holding = true;  // the thread that drains stays here until the test lets it go
      changed.wait_for(lock, std::chrono::seconds(10), [&] { return released; });
    };
  };
  dds::Reader<cell::Capability, cell::CapabilityPubSubType> reader(twin, "cell/capabilities", dds::TopicKind::state,
                                                                   saying('+'), saying('-'), slow);
  cell::Capability capability;
  auto b_side = dds::make_participant("test-b", settings);
  auto b = std::make_unique<CapabilityWriter>(b_side, "cell/capabilities", dds::TopicKind::state, slow);
  REQUIRE(b->wait_for_readers(1, std::chrono::seconds(10)));
  capability.resource_id("B");
  REQUIRE(b->write(capability));
  auto a_side = dds::make_participant("test-a", settings);
  CapabilityWriter a(a_side, "cell/capabilities", dds::TopicKind::state, slow);
  REQUIRE(a.wait_for_readers(1, std::chrono::seconds(10)));
  capability.resource_id("A");
  REQUIRE(a.write(capability));
  REQUIRE(wait_until([&] { return said.size() == 2; }));

  std::thread b_dies([&] {  // on a thread of its own: it may be the one held
    b.reset();
    b_side.reset();
  });
  struct LetGo {  // however the test ends: the reader let go, the thread joined
    std::function<void()> let_go;
    ~LetGo() { let_go(); }
  } let_go{[&] {
    {
      std::lock_guard<std::mutex> lock(mutex);
      released = true;
      changed.notify_all();
    }
    if (b_dies.joinable()) b_dies.join();
  }};
  REQUIRE(wait_until([&] { return holding; }));
  a.unregister(capability);
  REQUIRE(a.write(capability));
  let_go.let_go();
  wait_until([&] { return said.size() >= 5; });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // nothing more comes
  std::lock_guard<std::mutex> lock(mutex);
  CHECK(said == std::vector<std::string>{"+B", "+A", "-B", "-A", "+A"});
}

TEST_CASE("an outbox keeps what a stalled reader has no room for, and delivers it all in order once it reads again",
          "[dds]") {
  // Between two participants of one process Fast DDS delivers on the writer's thread, into the
  // reader's callback: the stalled reader would stall the writer, not fill its history.
  struct OwnThreads {
    eprosima::fastrtps::LibrarySettingsAttributes before = eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings();
    OwnThreads() {
      auto settings = before;
      settings.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_OFF;
      eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(settings);
    }
    ~OwnThreads() { eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(before); }
  } own_threads;
  const dds::ParticipantSettings settings{domains::kDdsOutbox, true, {}};
  auto station = dds::make_participant("test-station", settings);
  auto twin = dds::make_participant("test-twin", settings);
  dds::QosSettings small;
  small.max_queued = 4;
  std::mutex mutex;
  std::condition_variable changed;
  bool stalled = true;
  std::vector<std::string> got;
  dds::Reader<cell::CommandEvent, cell::CommandEventPubSubType> reader(
      twin, "cell/command_events", dds::TopicKind::events,
      [&](const cell::CommandEvent& e) {
        std::unique_lock<std::mutex> lock(mutex);
        changed.wait_for(lock, std::chrono::seconds(20), [&] { return !stalled; });  // a reader starved of CPU
        got.push_back(e.command_id().to_string());
        changed.notify_all();
      },
      {}, small);
  dds::Outbox<cell::CommandEvent, cell::CommandEventPubSubType> outbox(station, "cell/command_events",
                                                                      dds::TopicKind::events, small);
  REQUIRE(outbox.writer().wait_for_readers(1, std::chrono::seconds(10)));

  std::vector<std::string> sent;
  for (int i = 0; i < 16; ++i) {
    sent.push_back("c-" + std::to_string(i));
    CHECK(outbox.write(to_event({{"command_id", sent.back()}, {"t", 1.0}})));
  }
  // The writer alone would have failed these writes: its readers acknowledged no more.
  CHECK(outbox.flush() > 0);
  {
    std::lock_guard<std::mutex> lock(mutex);
    stalled = false;
    changed.notify_all();
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (outbox.flush() > 0 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::unique_lock<std::mutex> lock(mutex);
  CHECK(changed.wait_for(lock, std::chrono::seconds(20), [&] { return got.size() >= sent.size(); }));
  CHECK(got == sent);
}
