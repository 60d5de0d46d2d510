// Hostile and broken input over DDS, one kind per test on a domain of its own: a cell
// (`cellctl up`), an intruder's participant on the same domain that writes what it likes,
// the refusal or the survival asserted, and then a normal order on the same cell, which must
// still be assembled. Every process is ended by its id; every wait is bounded.

#include <condition_variable>
#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <optional>

#include <catch2/catch.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>

#include "capabilitiesPubSubTypes.h"
#include "commandsPubSubTypes.h"
#include "negotiationPubSubTypes.h"
#include "ordersPubSubTypes.h"
#include "services/dds/conversions.hpp"
#include "services/dds/endpoints.hpp"
#include "simulationPubSubTypes.h"
#include "tests/support/cell_test.hpp"
#include "tests/support/domains.hpp"
#include "tests/support/hire.hpp"
#include "tests/support/sanitizers.hpp"

namespace domains = test::domains;

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;


cell::Pose pose(double x, double y, double z, double qw = 1, double qx = 0, double qy = 0, double qz = 0) {
  cell::Pose p;
  p.position(dds::vec3(x, y, z));
  p.qw(qw);
  p.qx(qx);
  p.qy(qy);
  p.qz(qz);
  return p;
}

cell::Command command(const std::string& id, const std::string& resource, const std::string& order,
                      const std::string& operation, const std::string& award = "") {
  cell::Command c;
  c.command_id(id);
  c.resource_id(resource);
  c.order_id(order);
  c.operation(operation);
  c.award(award);
  return c;
}

// The default cell on `domain`, and an intruder on the same domain that sees the command
// events, capabilities, cell-sim replies and order states.
class HostileCell {
 public:
  HostileCell(int domain, const std::string& name)
      : domain_(std::to_string(domain)), dir_(test::scratch(name)),
        up_({CELLCTL_EXE, "up", "--domain", domain_, "--real-time-factor", "20", "--state-dir", (dir_ / "state").string()},
            (dir_ / "up.log").string()),
        intruder_(dds::make_participant("intruder", {domain, true, {}})) {
    events_ = std::make_unique<dds::Reader<cell::CommandEvent, cell::CommandEventPubSubType>>(
        intruder_, "cell/command_events", dds::TopicKind::events, [this](const cell::CommandEvent& e) {
          add([&] { events_of_[e.command_id().to_string()].push_back(e); });
        });
    capabilities_ = std::make_unique<dds::Reader<cell::Capability, cell::CapabilityPubSubType>>(
        intruder_, "cell/capabilities", dds::TopicKind::state,
        [this](const cell::Capability& c) { add([&] { capability_[c.resource_id().to_string()] = c; }); });
    sim_replies_ = std::make_unique<dds::Reader<cell::SimReply, cell::SimReplyPubSubType>>(
        intruder_, "cell/sim/replies", dds::TopicKind::events,
        [this](const cell::SimReply& r) { add([&] { sim_reply_[r.request_id().to_string()] = r; }); });
    statuses_ = std::make_unique<dds::Reader<cell::OrderStatus, cell::OrderStatusPubSubType>>(
        intruder_, "cell/orders/status", dds::TopicKind::state,
        [this](const cell::OrderStatus& s) { add([&] { order_state_[s.order_id().to_string()] = s.state(); }); });
    sim_requests_ = std::make_unique<dds::Writer<cell::SimRequest, cell::SimRequestPubSubType>>(
        intruder_, "cell/sim/requests", dds::TopicKind::events);
    const bool all_up = wait(60s, [&] {
      for (const auto& id : test::kDefaultCellResources) {
        if (!capability_.count(id)) return false;
      }
      return true;
    });
    INFO(test::read_text(dir_ / "up.log"));
    REQUIRE(all_up);
  }
  ~HostileCell() {
    test::cellctl({"down", "--domain", domain_}, dir_ / "down.log", 30s);
    up_.wait_for_exit(20s);
  }

  const dds::ParticipantPtr& intruder() const { return intruder_; }
  const fs::path& dir() const { return dir_; }
  const std::string& domain() const { return domain_; }
  pid_t up_pid() const { return up_.pid(); }

  // Writes a command on its resource's topic; false if the write failed.
  bool send(const cell::Command& c) {
    auto& writer = writers_[c.resource_id().to_string()];
    if (!writer) {
      writer = std::make_unique<dds::Writer<cell::Command, cell::CommandPubSubType>>(
          intruder_, dds::command_topic(c.resource_id().to_string()), dds::TopicKind::events, dds::command_qos());
      REQUIRE(writer->wait_for_readers(1, 10s));
    }
    return writer->write(c);
  }

  // Every event of the command once its final one came (empty if none came in time).
  std::vector<cell::CommandEvent> until_final(const std::string& id, std::chrono::seconds timeout = 15s) {
    const auto is_final = [](cell::CommandState s) {
      return s == cell::SUCCEEDED || s == cell::ABORTED || s == cell::CANCELED || s == cell::REJECTED;
    };
    std::vector<cell::CommandEvent> out;
    wait(timeout, [&] {
      const auto it = events_of_.find(id);
      if (it == events_of_.end() || !is_final(it->second.back().state())) return false;
      out = it->second;
      return true;
    });
    return out;
  }

  std::size_t finals_among(const std::vector<std::string>& ids) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::size_t n = 0;
    for (const auto& id : ids) {
      const auto it = events_of_.find(id);
      if (it != events_of_.end() && (it->second.back().state() == cell::SUCCEEDED ||
                                     it->second.back().state() == cell::REJECTED ||
                                     it->second.back().state() == cell::ABORTED)) {
        ++n;
      }
    }
    return n;
  }

  cell::Capability capability(const std::string& id) {
    std::lock_guard<std::mutex> lock(mutex_);
    return capability_.at(id);
  }
  // Inside wait()'s predicate, which holds the lock: a body of the order that its commands name.
  std::string part_of_unlocked(const std::string& order) const {
    for (const auto& [id, events] : events_of_) {
      for (const auto& e : events) {
        if (e.order_id() == order && e.part().size() > 0) return e.part().to_string();
      }
    }
    return "";
  }
  // Inside wait()'s predicate, which holds the lock.
  const cell::Capability& capability_unlocked(const std::string& id) const {
    static const cell::Capability none;
    const auto it = capability_.find(id);
    return it == capability_.end() ? none : it->second;
  }

  template <class Pred>
  bool wait(std::chrono::milliseconds timeout, Pred pred) {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, timeout, pred);
  }

  // cell-sim's answer to a request of the intruder's: "" if done, otherwise why not.
  std::string ask_sim(cell::SimRequest r) {
    static int count = 0;
    const std::string id = "intruder/sim/" + std::to_string(++count);
    r.request_id(id);
    r.requester("intruder");
    REQUIRE(sim_requests_->wait_for_readers(1, 10s));
    REQUIRE(sim_requests_->write(r));
    std::optional<cell::SimReply> reply;
    wait(10s, [&] {
      const auto it = sim_reply_.find(id);
      if (it != sim_reply_.end()) reply = it->second;
      return reply.has_value();
    });
    REQUIRE(reply);
    return reply->ok() ? "" : reply->error().to_string();
  }

  // A normal order on the same cell, to its end: whether it was assembled.
  bool order_succeeds(const std::string& order) {
    const int code = test::cellctl({"submit", test::kLegoTower, "--domain", domain_, "--order", order, "--out",
                                    (dir_ / order).string()},
                                   dir_ / (order + ".log"));
    INFO(test::read_text(dir_ / (order + ".log")));
    return code == 0;
  }

  // A normal order started in the background (ended by its id at the end of the test).
  std::unique_ptr<test::ChildProcess> start_order(const std::string& order) {
    return std::make_unique<test::ChildProcess>(
        std::vector<std::string>{CELLCTL_EXE, "submit", test::kLegoTower, "--domain", domain_, "--order", order, "--out",
                                 (dir_ / order).string()},
        (dir_ / (order + ".log")).string());
  }

  bool order_reaches(const std::string& order, cell::OrderState state, std::chrono::seconds timeout = 60s) {
    return wait(timeout, [&] {
      const auto it = order_state_.find(order);
      return it != order_state_.end() && it->second == state;
    });
  }

  // The resident memory of each cell process, kB, by name.
  std::map<std::string, long> rss() const {
    std::map<std::string, long> out;
    for (const auto& [name, pid] : test::children_of(up_.pid())) out[name] += test::rss_kb(pid);
    return out;
  }

  // rss() once no process's has changed by 1 MB or more in a second (at most 60 s): a
  // process still starting (the standby twin joins the cell after the resources, slowly
  // under ThreadSanitizer) is not measured while it grows.
  std::map<std::string, long> settled_rss() const {
    auto last = rss();
    for (int i = 0; i < 60; ++i) {
      std::this_thread::sleep_for(1s);
      auto now = rss();
      bool settled = now.size() == last.size();
      for (const auto& [name, kb] : now) {
        const auto it = last.find(name);
        settled = settled && it != last.end() && std::abs(kb - it->second) < 1024;
      }
      last = std::move(now);
      if (settled) break;
    }
    return last;
  }

 private:
  template <class F>
  void add(F f) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      f();
    }
    changed_.notify_all();
  }

  std::string domain_;
  fs::path dir_;
  test::ChildProcess up_;
  dds::ParticipantPtr intruder_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::map<std::string, std::vector<cell::CommandEvent>> events_of_;
  std::map<std::string, cell::Capability> capability_;
  std::map<std::string, cell::SimReply> sim_reply_;
  std::map<std::string, cell::OrderState> order_state_;
  std::unique_ptr<dds::Reader<cell::CommandEvent, cell::CommandEventPubSubType>> events_;
  std::unique_ptr<dds::Reader<cell::Capability, cell::CapabilityPubSubType>> capabilities_;
  std::unique_ptr<dds::Reader<cell::SimReply, cell::SimReplyPubSubType>> sim_replies_;
  std::unique_ptr<dds::Reader<cell::OrderStatus, cell::OrderStatusPubSubType>> statuses_;
  std::unique_ptr<dds::Writer<cell::SimRequest, cell::SimRequestPubSubType>> sim_requests_;
  std::map<std::string, std::unique_ptr<dds::Writer<cell::Command, cell::CommandPubSubType>>> writers_;
};

// The one event a refused command gets: REJECTED, with its reason.
std::string rejection(HostileCell& cell, const std::string& id) {
  const auto events = cell.until_final(id);
  REQUIRE(events.size() == 1);
  CHECK(events[0].state() == cell::REJECTED);
  return events[0].reason().to_string();
}

cell::CommandState final_state(HostileCell& cell, const std::string& id) {
  const auto events = cell.until_final(id);
  REQUIRE(!events.empty());
  UNSCOPED_INFO(id << " ended " << dds::state_name(events.back().state()) << " " << events.back().reason().to_string());
  return events.back().state();
}

// The intruder hires arm-1 as a twin would, and grips: the arm's gripper stands at the station.
std::string hire_arm_and_grip(HostileCell& cell) {
  std::string why;
  const std::string award = test::hire(cell.intruder(), "arm-1", "rogue", "translate", {"station-1", "", 0}, &why);
  INFO(why);
  REQUIRE(award == "rogue/translate/arm-1");
  cell::Command grip = command("rogue/grip", "arm-1", "rogue", "grip", award);  // closing on nothing
  grip.path({pose(0, 0.3, 0)});
  grip.opening(0.02);
  REQUIRE(cell.send(grip));
  REQUIRE(final_state(cell, "rogue/grip") == cell::SUCCEEDED);
  return award;
}

cell::Command translate(const std::string& id, const std::string& award, const cell::Pose& to) {
  cell::Command c = command(id, "arm-1", "rogue", "translate", award);
  c.path({to});
  return c;
}

// The intruder lets the arm go, as a twin does at its end.
void release_arm(HostileCell& cell) {
  dds::Writer<cell::Release, cell::ReleasePubSubType> releases(cell.intruder(), "cell/negotiation/releases",
                                                               dds::TopicKind::events);
  REQUIRE(releases.wait_for_readers(1, 10s));
  cell::Release r;
  r.order_id("rogue");
  r.resource_id("arm-1");
  REQUIRE(releases.write(r));
  REQUIRE(cell.wait(10s, [&] { return cell.capability_unlocked("arm-1").reserved_by().size() == 0; }));
}

// A translate with a bad pose from the order that holds the arm: rejected with the field,
// the arm neither busy nor wedged (a valid move after it succeeds), cell-sim still answering.
void bad_pose_is_rejected(int domain, const std::string& name, const cell::Pose& bad, const std::string& reason) {
  HostileCell cell(domain, name);
  const std::string award = hire_arm_and_grip(cell);
  REQUIRE(cell.send(translate("rogue/bad", award, bad)));
  CHECK(rejection(cell, "rogue/bad") == reason);
  CHECK_FALSE(cell.capability("arm-1").busy());
  REQUIRE(cell.send(translate("rogue/good", award, pose(0.1, 0.3, 0))));
  CHECK(final_state(cell, "rogue/good") == cell::SUCCEEDED);
  release_arm(cell);
  CHECK(cell.order_succeeds("ok1"));
}

}  // namespace

TEST_CASE("hostile: a translate to a NaN position is rejected, the arm stays free", "[process][hostile]") {
  bad_pose_is_rejected(210, "nan-position", pose(std::nan(""), 0.3, 0), "path[0]: position (nan, 0.3, 0) is not finite");
}

TEST_CASE("hostile: a translate with a NaN quaternion is rejected", "[process][hostile]") {
  bad_pose_is_rejected(211, "nan-quaternion", pose(0.1, 0.3, 0, std::nan(""), 0, 0, 0),
                       "path[0]: orientation is not finite");
}

TEST_CASE("hostile: a translate to x = +inf is rejected", "[process][hostile]") {
  bad_pose_is_rejected(212, "infinite", pose(HUGE_VAL, 0.3, 0), "path[0]: position (inf, 0.3, 0) is not finite");
}

TEST_CASE("hostile: a grip of negative, NaN or too wide an opening is rejected", "[process][hostile]") {
  HostileCell cell(domains::kHostileOpening, "bad-opening");
  const std::string award = hire_arm_and_grip(cell);
  for (const double opening : {-0.01, std::nan(""), 5.0}) {
    cell::Command grip = command("rogue/grip-" + std::to_string(opening), "arm-1", "rogue", "grip", award);
    grip.part("rogue/nothing");
    grip.path({pose(0, 0.3, 0)});
    grip.opening(opening);
    REQUIRE(cell.send(grip));
    CHECK(rejection(cell, grip.command_id().to_string()).find("opening: ") == 0);
  }
  release_arm(cell);
  CHECK(cell.order_succeeds("ok1"));
}

TEST_CASE("hostile: a path of 1,000,000 waypoints is dropped by DDS, and no process keeps the memory",
          "[process][hostile]") {
  HostileCell cell(domains::kHostileHugePath, "huge-path");
  const auto before = cell.settled_rss();
  {
    // The intruder's own writer, whose buffers grow to whatever it writes.
    namespace fdds = eprosima::fastdds::dds;
    fdds::TypeSupport type(new cell::CommandPubSubType());
    auto* topic = dds::topic_on<cell::CommandPubSubType>(*cell.intruder(), dds::command_topic("arm-1"));
    auto* publisher = cell.intruder()->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
    fdds::DataWriterQos qos = dds::writer_qos(dds::TopicKind::events);
    qos.endpoint().history_memory_policy = eprosima::fastrtps::rtps::DYNAMIC_RESERVE_MEMORY_MODE;
    auto* writer = publisher->create_datawriter(topic, qos);
    REQUIRE(writer);
    cell::Command huge = command("rogue/huge", "arm-1", "rogue", "translate", "rogue/translate/arm-1");
    huge.path(std::vector<cell::Pose>(1000000, pose(0, 0.3, 0)));
    CHECK(writer->write(&huge));
    std::this_thread::sleep_for(3s);
    publisher->delete_datawriter(writer);
    cell.intruder()->delete_publisher(publisher);
  }
  CHECK(cell.until_final("rogue/huge", 1s).empty());  // never reached the arm
  const auto after = cell.rss();
  for (const auto& [name, kb] : before) {
    INFO(name << ": " << kb << " kB before, " << after.at(name) << " kB after");
    CHECK(after.at(name) < kb + 10 * 1024);  // not the sample's 56 MB, nor a part of it
  }
  CHECK(cell.order_succeeds("ok1"));
}

TEST_CASE("hostile: a fetch for an order that hired no robot is rejected before the robot moves", "[process][hostile]") {
  HostileCell cell(domains::kHostileUnhiredFetch, "unhired-fetch");
  cell::Command fetch = command("rogue/fetch", "mobile-robot-1", "rogue", "fetch", "rogue/robot");
  fetch.part("rogue/x");
  fetch.part_type("Unobtainium");
  fetch.source("buffer-1");
  fetch.destination("station-1");
  fetch.source_award("rogue/give");
  REQUIRE(cell.send(fetch));
  CHECK(rejection(cell, "rogue/fetch") == "mobile-robot-1 has no award rogue/robot of order rogue");
  CHECK(cell.wait(10s, [&] { return cell.capability_unlocked("mobile-robot-1").refused_commands() >= 1; }));
  CHECK(cell.order_succeeds("ok1"));
}

TEST_CASE("hostile: a give without an award is rejected and the stock stays", "[process][hostile]") {
  HostileCell cell(domains::kHostileUnawardedGive, "unawarded-give");
  const auto stock = [&] { return cell.capability("buffer-2").stock(); };
  const auto before = stock();
  cell::Command give = command("rogue/give", "buffer-2", "rogue", "give", "rogue/give/Brick2x4");
  give.part_type("Brick2x4");
  give.destination("rogue-robot");
  REQUIRE(cell.send(give));
  CHECK(rejection(cell, "rogue/give") == "buffer-2 has no award rogue/give/Brick2x4 of order rogue");
  CHECK(stock() == before);
  CHECK(cell.wait(10s, [&] {
    return cell.capability_unlocked("buffer-2").last_refusal().to_string().find("rogue rogue/give: buffer-2 has no award") == 0;
  }));
  CHECK(cell.order_succeeds("ok1"));
}

TEST_CASE("hostile: a command from an intruder while an order holds the arm is rejected, the order goes on",
          "[process][hostile]") {
  HostileCell cell(domains::kHostileIntruderCommand, "intruder-command");
  auto ok1 = cell.start_order("ok1");
  REQUIRE(cell.order_reaches("ok1", cell::PHYSICAL_ASSEMBLY));
  cell::Command move = command("intruder/move", "arm-1", "intruder", "translate", "intruder/arm");
  move.part("ok1/B1");
  move.path({pose(0.5, 0.5, 0)});
  REQUIRE(cell.send(move));
  CHECK(rejection(cell, "intruder/move") == "arm-1 is reserved by ok1");
  const int code = ok1->wait_for_exit(120s);
  INFO(test::read_text(cell.dir() / "ok1.log"));
  CHECK(code == 0);
}

TEST_CASE("hostile: cell-sim refuses an intruder's changes to an order's parts, the order goes on", "[process][hostile]") {
  HostileCell cell(domains::kHostileIntruderSim, "intruder-sim");
  auto ok1 = cell.start_order("ok1");
  REQUIRE(cell.order_reaches("ok1", cell::PHYSICAL_ASSEMBLY));
  // A part of the order's in the physical cell, as the resources' events name it.
  std::string part;
  REQUIRE(cell.wait(30s, [&] {
    part = cell.part_of_unlocked("ok1");
    return !part.empty();
  }));
  cell::SimRequest remove;
  remove.kind("remove");
  remove.body_id(part);
  CHECK(cell.ask_sim(remove) == part + " belongs to ok1, not to intruder");
  cell::SimRequest movable;
  movable.kind("set_movable");
  movable.body_id(part);
  CHECK(cell.ask_sim(movable) == part + " belongs to ok1, not to intruder");
  cell::SimRequest move;
  move.kind("move");
  move.body_id(part);
  move.order_id("ok1");
  move.path({pose(2, 0.5, 0)});
  move.speed(1);
  CHECK(cell.ask_sim(move) == part + " belongs to order ok1, which has not hired intruder");
  cell::SimRequest table;
  table.kind("remove");
  table.body_id("station-1/table");
  CHECK(cell.ask_sim(table) == "station-1/table is a fixture of the cell");
  // cell-sim's line in the cell's status says so.
  CHECK(cell.wait(10s, [&] {
    const cell::Capability& sim = cell.capability_unlocked("cell-sim");
    return sim.refused_commands() >= 4 &&
           sim.last_refusal().to_string().find(": station-1/table is a fixture of the cell") != std::string::npos;
  }));
  const int code = ok1->wait_for_exit(120s);
  INFO(test::read_text(cell.dir() / "ok1.log"));
  CHECK(code == 0);
}

TEST_CASE("hostile: a burst of 10,000 commands: each gets a final event, the station lives and gives its memory back",
          "[process][hostile]") {
  HostileCell cell(domains::kHostileBurst, "burst");
  const long before = cell.settled_rss().at("station");
  std::vector<std::string> written;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 10000; ++i) {
    const std::string id = "intruder/release/" + std::to_string(i);
    if (cell.send(command(id, "arm-1", "intruder", "release", "intruder/arm"))) written.push_back(id);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  INFO(written.size() << " of 10000 written in " << seconds << " s");
  CHECK(written.size() >= 9000);
  const auto all_answered = [&] { return cell.finals_among(written) == written.size(); };
  for (int i = 0; i < 600 && !all_answered(); ++i) std::this_thread::sleep_for(100ms);
  CHECK(cell.finals_among(written) == written.size());
  CHECK(cell.wait(10s, [&] {
    return cell.capability_unlocked("arm-1").refused_commands() >= static_cast<int>(written.size());
  }));
  std::this_thread::sleep_for(2s);
  const long after = cell.rss().at("station");
  INFO("station " << before << " kB before, " << after << " kB after");
  if (test::kUnderSanitizers) {
    WARN("memory not checked under a sanitizer");
  } else {
    // What stays is the allocator's and DDS's, not the burst's: 1.8-2.8 MB after 10,000
    // commands and after 30,000 alike; before the command queue was bounded, 33 MB.
    CHECK(after <= before + 5 * 1024);
  }
  CHECK(cell.order_succeeds("ok1"));
}
