// The twin's application (OrderOrchestrator and Negotiator) driven with events and no DDS: a
// stand-in cell bids for every call, answers every cell-sim request and command, and refuses
// what the test says.

#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <thread>

#include <catch2/catch.hpp>

#include "tests/twin/test_support.hpp"
#include "twin/orchestration/order_network.hpp"

namespace {

using fb::Data;
using fb::get;

// Takes every event the twin's blocks send out.
class Outbox : public fb::FunctionBlock {
 public:
  Outbox() : FunctionBlock("outbox") {
    for (const char* e : {"RELEASE", "COMMAND", "CANCEL", "SIM", "STATUS", "FINDING", "QUOTE", "FINISHED", "CFP", "AWARD",
                          "PLACED"}) {
      declare_input(e);
    }
  }
  void receive(const fb::Event& event) override { events.push_back(event); }
  std::vector<fb::Event> events;
};

struct Twin {
  Twin(const twin::LoadedProduct& product, const twin::Plan& plan, bool quote_only = false,
       twin::Resume resume = {}, std::chrono::milliseconds resend_after = std::chrono::seconds(2),
       std::chrono::milliseconds wait_timeout = std::chrono::seconds(30))
      : resource("twin", 4096) {
    twin::OrderSettings order;
    order.order_id = "o1";
    order.resend_after = resend_after;
    order.wait_timeout = wait_timeout;
    order.quote_only = quote_only;
    order.resume = std::move(resume);
    fb::NegotiationSettings negotiation;
    negotiation.quote_patience = std::chrono::milliseconds(0);  // a refused call for quotes ends at the next TICK
    orchestrator = &twin::add_order_network(resource, product, plan, order, negotiation);
    outbox = &resource.add(std::make_unique<Outbox>());
    for (const char* e : {"RELEASE", "COMMAND", "CANCEL", "SIM", "STATUS", "FINDING", "QUOTE", "FINISHED", "PLACED"}) {
      resource.connect("orchestrator", e, "outbox", e);
    }
    for (const char* e : {"CFP", "AWARD"}) resource.connect("negotiator", e, "outbox", e);
  }
  std::vector<fb::Event> send(const std::string& block, const std::string& input, Data data = {}) {
    outbox->events.clear();
    resource.post(block, input, std::move(data));
    resource.run_until_idle();
    return outbox->events;
  }
  fb::Resource resource;
  twin::OrderOrchestrator* orchestrator = nullptr;
  Outbox* outbox = nullptr;
};

struct Outcome {
  std::vector<std::string> findings;  // kinds
  std::vector<std::string> canceled;  // command ids
  std::vector<std::string> spawned;   // bodies, in order
  std::vector<std::string> statuses;  // messages
  std::vector<std::string> order;     // what went out: "SIM spawn", "CFP host", ...
  std::vector<Data> grips;            // the grip commands
  std::vector<Data> placed;           // PLACED events
  std::vector<Data> moves;            // cell-sim moves
  std::vector<Data> calls;            // the CFPs
  std::optional<Data> quote;
  bool finished = false, complete = false;
  std::string error;
};

// The stand-in cell's answers. `collide(move, parts placed so far)`: a cell-sim move that collides;
// `refuse(command)`: a reason to abort a command with (empty: it succeeds; kNoAnswer: it is
// never answered; kAcceptOnly: accepted, and never more); `ticks`: TICKs for the orchestrator
// when nothing else is under way (its resends); `ahead`: the station's queue before this order; `turns_ours`: the station
// that is reserved for the order once it said it waits (another than station-1: the booking
// an earlier twin of the order left there); `busy(request)`: cell-sim answers it "busy".
const std::string kNoAnswer = "(no answer)";
const std::string kAcceptOnly = "(accepted only)";
struct Cell {
  std::function<bool(const Data&, long)> collide = [](const Data&, long) { return false; };
  std::function<std::string(const Data&)> refuse = [](const Data&) { return std::string(); };
  std::function<std::string(const Data&)> refuse_call = [](const Data&) { return std::string(); };  // a CFP
  std::function<bool(const Data&)> busy = [](const Data&) { return false; };  // cell-sim's queue full
  std::function<bool(const Data&)> silent = [](const Data&) { return false; };  // cell-sim never answers it
  // station-1 is gone (its lease ran out) before this event, and back before the next call.
  std::function<bool(const fb::Event&)> station_leaves = [](const fb::Event&) { return false; };
  std::chrono::milliseconds tick_pause{0};  // wall time before each of the orchestrator's TICKs
  std::function<bool(const fb::Event&)> stop_before = [](const fb::Event&) { return false; };  // the operator cancels
  long ahead = 0;
  std::string turns_ours = "station-1";
  int ticks = 0;
};

Outcome run(Twin& t, const Cell& cell) {
  Outcome out;
  const auto capability = [&](const std::string& id, const std::string& kind, const std::string& ops,
                              const std::string& holder) {
    const Data c{{"resource_id", id},         {"kind", kind},           {"operations", ops},
                 {"position", fb::Numbers{0, 0, 0}}, {"dock", fb::Numbers{0.6, 0, 0}}, {"speed", 0.25},
                 {"angular_speed", 1.0},       {"reserved_by", holder},  {"waiting", std::string()}};
    std::vector<fb::Event> out = t.send("negotiator", "CAPABILITY", c);
    const auto more = t.send("orchestrator", "CAPABILITY", c);
    out.insert(out.end(), more.begin(), more.end());
    return out;
  };
  capability("station-1", "station", "host", "");
  capability("arm-1", "arm", "grip,translate", "");
  capability("mobile-robot-1", "mobile-robot", "fetch", "");
  capability("buffer-1", "buffer", "give", "");
  std::vector<fb::Event> pending = t.send("orchestrator", "START");
  bool queued_reported = false, ticked = false, station_away = false;
  int ticks_left = cell.ticks;
  for (int guard = 0; guard < 100000; ++guard) {
    if (pending.empty() && !out.finished && !ticked) {
      ticked = true;
      pending = t.send("negotiator", "TICK");
      continue;
    }
    if (pending.empty() && !out.finished && ticks_left > 0) {
      --ticks_left;
      std::this_thread::sleep_for(cell.tick_pause);
      pending = t.send("orchestrator", "TICK");
      continue;
    }
    if (pending.empty()) {
      // The station's queue moves on once the order has said it waits.
      if (cell.ahead == 0 || !queued_reported || out.finished) break;
      queued_reported = false;
      pending = capability(cell.turns_ours, "station", "host", "o1");
      continue;
    }
    const fb::Event e = pending.front();
    pending.erase(pending.begin());
    if (cell.station_leaves(e)) {
      t.send("orchestrator", "RESOURCE_GONE", {{"resource_id", std::string("station-1")}});
      station_away = true;
    }
    if (station_away && e.name == "CFP") {
      station_away = false;
      const auto back = capability("station-1", "station", "host", "");
      pending.insert(pending.end(), back.begin(), back.end());
    }
    if (cell.stop_before(e)) {
      const auto stopped = t.send("orchestrator", "STOP", {{"reason", std::string("cancelled by the operator (test)")}});
      pending.insert(pending.end(), stopped.begin(), stopped.end());
    }
    std::vector<fb::Event> more;
    if (e.name == "CFP") {
      const std::string& op = get<std::string>(e.data, "operation");
      out.order.push_back("CFP " + op);
      out.calls.push_back(e.data);
      const std::string& only = get<std::string>(e.data, "station");
      const std::string resource = op == "host" ? (only.empty() ? "station-1" : only) : op == "translate" ? "arm-1"
                                 : op == "fetch" ? "mobile-robot-1" : "buffer-1";
      const std::string no = cell.refuse_call(e.data);
      more = t.send("negotiator", "PROPOSAL", {{"call_id", e.data.at("call_id")}, {"resource_id", resource},
                                               {"available", no.empty()}, {"reason", no},
                                               {"earliest_start", 0.0}, {"duration", 1.0}});
      if (op == "host" && resource != "station-1") {  // a call for one station: the other says no
        const auto refusal = t.send("negotiator", "PROPOSAL", {{"call_id", e.data.at("call_id")}, {"resource_id", std::string("station-1")},
                                                               {"available", false}, {"reason", std::string("not station-1")},
                                                               {"earliest_start", 0.0}, {"duration", 0.0}});
        more.insert(more.end(), refusal.begin(), refusal.end());
      }
    } else if (e.name == "QUOTE") {
      out.quote = e.data;
    } else if (e.name == "AWARD") {
      out.order.push_back("AWARD " + get<std::string>(e.data, "resource_id"));
      const bool host = get<std::string>(e.data, "resource_id") == "station-1";
      more = t.send("negotiator", "AWARD_REPLY", {{"call_id", e.data.at("call_id")},
                                                  {"resource_id", e.data.at("resource_id")}, {"confirmed", true},
                                                  {"reason", std::string()},
                                                  {"ahead", std::int64_t(host ? cell.ahead : 0)}});
    } else if (e.name == "SIM") {
      const std::string& kind = get<std::string>(e.data, "kind");
      out.order.push_back("SIM " + kind);
      if (kind == "spawn") out.spawned.push_back(get<std::string>(e.data, "body_id"));
      if (kind == "move") out.moves.push_back(e.data);
      if (cell.silent(e.data)) continue;
      if (cell.busy(e.data)) {
        more = t.send("orchestrator", "SIM_REPLY",
                      {{"request_id", e.data.at("request_id")}, {"ok", false},
                       {"error", std::string("busy: cell-sim's event queue is full (4096 events); ask again")},
                       {"collided", false}});
        pending.insert(pending.end(), more.begin(), more.end());
        continue;
      }
      const bool collided = kind == "move" && cell.collide(e.data, std::count(out.order.begin(), out.order.end(), "SIM set_static"));
      more = t.send("orchestrator", "SIM_REPLY",
                    {{"request_id", e.data.at("request_id")}, {"ok", true}, {"error", std::string()},
                     {"collided", collided}, {"hit_body", std::string("B1")}, {"hit_member", std::string("it")},
                     {"depth", 0.001}, {"start_time", 0.0}, {"end_time", 1.0}, {"distance", 0.1}});
    } else if (e.name == "COMMAND") {
      out.order.push_back("COMMAND " + get<std::string>(e.data, "operation"));
      if (get<std::string>(e.data, "operation") == "grip") out.grips.push_back(e.data);
      const std::string reason = cell.refuse(e.data);
      if (reason == kNoAnswer) continue;
      const char* state = reason.empty() ? "succeeded" : reason == kAcceptOnly ? "accepted" : "aborted";
      more = t.send("orchestrator", "COMMAND_EVENT", {{"command_id", e.data.at("command_id")},
                                                      {"order_id", e.data.at("order_id")},
                                                      {"state", std::string(state)},
                                                      {"reason", reason == kAcceptOnly ? std::string() : reason}});
    } else if (e.name == "RELEASE") {
      out.order.push_back("RELEASE " + get<std::string>(e.data, "resource_id"));
    } else if (e.name == "CANCEL") {
      out.canceled.push_back(get<std::string>(e.data, "command_id"));
    } else if (e.name == "STATUS") {
      out.statuses.push_back(get<std::string>(e.data, "message"));
      queued_reported |= out.statuses.back().find("orders ahead") != std::string::npos;
    } else if (e.name == "PLACED") {
      out.order.push_back("PLACED");
      out.placed.push_back(e.data);
    } else if (e.name == "FINDING") {
      out.findings.push_back(get<std::string>(e.data, "kind"));
    } else if (e.name == "FINISHED") {
      out.finished = true;
      out.complete = get<bool>(e.data, "complete");
      out.error = get<std::string>(e.data, "error");
    }
    pending.insert(pending.end(), more.begin(), more.end());
  }
  return out;
}

bool carries(const Data& move, const std::string& body) {
  const auto carried = fb::split_names(get<std::string>(move, "carried"));
  return std::find(carried.begin(), carried.end(), body) != carried.end();
}

}  // namespace

TEST_CASE("orchestrator: virtual assembly in the order's own scene first, holding nothing, then a station",
          "[twin][orchestration]") {
  const test::Planned cranfield(test::product("cranfield/cranfield.aml"));
  Twin t(cranfield.product, cranfield.plan);
  const Outcome out = run(t, Cell{});
  INFO(out.error);
  CHECK(out.complete);
  // Nothing is called for before every virtual part stands; the station comes first.
  const auto first_call = std::find_if(out.order.begin(), out.order.end(), [](const std::string& s) { return s.rfind("CFP", 0) == 0; });
  REQUIRE(first_call != out.order.end());
  CHECK(*first_call == "CFP host");
  const long static_parts = std::count(out.order.begin(), first_call, "SIM set_static");
  CHECK(static_parts == static_cast<long>(cranfield.plan.steps.size()));
  CHECK(std::find(out.order.begin(), first_call, "COMMAND grip") == first_call);  // no arm in virtual assembly
  // The hired robot gets one fetch per part, the arm one grip per part.
  CHECK(std::count(out.order.begin(), out.order.end(), "COMMAND fetch") == static_cast<long>(cranfield.plan.steps.size()));
  CHECK(std::count(out.order.begin(), out.order.end(), "COMMAND grip") == static_cast<long>(cranfield.plan.steps.size()));
  // A part is recorded in place as soon as the arm has let it go at its final pose, before
  // the gripper backs out: a twin that dies then leaves it standing for the next one.
  CHECK(std::count(out.order.begin(), out.order.end(), "PLACED") == static_cast<long>(cranfield.plan.steps.size()));
  for (auto at = std::find(out.order.begin(), out.order.end(), "COMMAND release"); at != out.order.end();
       at = std::find(at + 1, out.order.end(), "COMMAND release")) {
    REQUIRE(at + 1 != out.order.end());
    CHECK(*(at + 1) == "PLACED");
  }
  // Virtual and physical assembly hold each part by the planned grasp: the gripper's four
  // bodies in cell-sim, the arm's grip as wide and turned as the plan's.
  for (const char* body : {"o1/virtual/gripper-palm", "o1/virtual/gripper-finger-1", "o1/virtual/gripper-finger-2",
                           "o1/virtual/gripper-carriage"}) {
    CHECK(std::count(out.spawned.begin(), out.spawned.end(), body) == static_cast<long>(cranfield.plan.steps.size()));
  }
  REQUIRE(out.grips.size() == cranfield.plan.steps.size());
  for (std::size_t k = 0; k < out.grips.size(); ++k) {
    const twin::Trajectory& planned = cranfield.plan.steps[k].trajectory;
    INFO("step " << k + 1 << ": " << planned.grasp.label);
    CHECK(get<double>(out.grips[k], "opening") == Approx(planned.grasp.opening));
    const fb::Numbers& pose = get<fb::Numbers>(out.grips[k], "path");
    REQUIRE(pose.size() == 7);
    const twin::Quat turned(pose[3], pose[4], pose[5], pose[6]);
    CHECK(turned.angularDistance(twin::Quat(planned.waypoints.front().gripper.linear())) < 1e-9);
  }
  // The front plate stands only pressed on (its plan step holds it): connected before the
  // arm lets go. Every other part is let go, then connected.
  std::vector<std::string> arm;
  for (const auto& s : out.order) {
    if (s == "COMMAND grip" || s == "COMMAND release" || s == "COMMAND connect") arm.push_back(s.substr(8));
  }
  std::vector<std::string> expected;
  for (const auto& step : cranfield.plan.steps) {
    const std::vector<std::string> sequence =
        step.hold ? std::vector<std::string>{"grip", "connect", "release"} : std::vector<std::string>{"grip", "release", "connect"};
    expected.insert(expected.end(), sequence.begin(), sequence.end());
  }
  CHECK(cranfield.plan.steps.back().hold);
  CHECK(arm == expected);
}

TEST_CASE("orchestrator: a subassembly is built aside, then gripped by its base and inserted whole, virtually and physically",
          "[twin][orchestration][subassembly]") {
  const test::Planned nested(std::filesystem::path(TEST_DATA_DIR) / "planning/cranfield-subassembly/cranfield-subassembly.aml",
                             test::with_fixtures());
  const twin::Plan& plan = nested.plan;
  REQUIRE(plan.complete);
  REQUIRE(plan.subassemblies.size() == 1);
  const twin::SubassemblyPlan& unit = plan.subassemblies.front();
  const auto& parts = nested.product.product.parts();
  const std::size_t part_count = parts.size();
  REQUIRE(plan.steps.size() == part_count + 1);  // each part, and the step inserting the unit
  Twin t(nested.product, plan);
  const Outcome out = run(t, Cell{});
  INFO(out.error);
  REQUIRE(out.complete);

  // Virtual assembly: the unit's insertion moves every member with the gripper.
  const auto inserting = std::find_if(out.moves.begin(), out.moves.end(), [&](const Data& move) {
    return std::all_of(unit.members.begin(), unit.members.end(),
                       [&](twin::PartIndex p) { return carries(move, "o1/virtual/" + parts[p].name); });
  });
  CHECK(inserting != out.moves.end());

  // Physical: one fetch per part, none for the unit; one grip per step.
  CHECK(std::count(out.order.begin(), out.order.end(), "COMMAND fetch") == static_cast<long>(part_count));
  REQUIRE(out.grips.size() == plan.steps.size());
  std::vector<std::string> members;
  for (twin::PartIndex p : unit.members) members.push_back("o1/" + parts[p].name);
  const auto unit_grip = std::find_if(out.grips.begin(), out.grips.end(),
                                      [](const Data& g) { return !get<std::string>(g, "carried").empty(); });
  REQUIRE(unit_grip != out.grips.end());
  CHECK(get<std::string>(*unit_grip, "part") == members.front());  // by its base
  CHECK(fb::split_names(get<std::string>(*unit_grip, "carried")) == std::vector<std::string>(members.begin() + 1, members.end()));
  // Built aside and connected there: each member is made movable before the grip, and
  // connected again after the insertion.
  CHECK(std::count(out.order.begin(), out.order.end(), "COMMAND disconnect") == static_cast<long>(members.size()));
  CHECK(std::count(out.order.begin(), out.order.end(), "COMMAND connect") == static_cast<long>(part_count + members.size()));

  // The members are recorded in their subassembly aside, then in place all at once.
  REQUIRE(out.placed.size() == plan.steps.size());
  std::vector<std::string> aside, inserted;
  for (const Data& placed : out.placed) {
    if (get<std::string>(placed, "aside") == unit.name) aside.push_back(get<std::string>(placed, "part"));
    if (fb::split_names(get<std::string>(placed, "part")).size() > 1) {
      CHECK(get<std::string>(placed, "aside").empty());
      inserted = fb::split_names(get<std::string>(placed, "part"));
    }
  }
  CHECK(aside == members);
  CHECK(inserted == members);
}

TEST_CASE("orchestrator: a subassembly that finds no way in cell-sim fails the order, every try said", "[twin][orchestration][subassembly]") {
  const test::Planned nested(std::filesystem::path(TEST_DATA_DIR) / "planning/cranfield-subassembly/cranfield-subassembly.aml",
                             test::with_fixtures());
  REQUIRE(nested.plan.complete);
  const auto unit = std::find_if(nested.plan.steps.begin(), nested.plan.steps.end(), [](const auto& s) { return !s.carried.empty(); });
  REQUIRE(unit != nested.plan.steps.end());
  Twin t(nested.product, nested.plan);
  Cell cell;  // every move of the whole subassembly collides
  cell.collide = [](const Data& move, long) { return carries(move, "o1/virtual/shaft") && carries(move, "o1/virtual/pendulum"); };
  const Outcome out = run(t, cell);
  CHECK(out.finished);
  CHECK_FALSE(out.complete);
  CHECK(out.error.find("no collision-free path in cell-sim for ShaftPendulum (shaft, pendulum)") != std::string::npos);
  CHECK(out.error.find("not planned again") != std::string::npos);
  CHECK(std::count(out.findings.begin(), out.findings.end(), "collision") == static_cast<long>(unit->failed.size() + 1));
  CHECK(std::find(out.order.begin(), out.order.end(), "CFP host") == out.order.end());  // never booked a station
}

TEST_CASE("orchestrator: a queued order says how many are ahead, and goes on when the station is its", "[twin][orchestration]") {
  const test::Planned lego(test::product("lego-tower/lego-tower.aml"));
  Twin t(lego.product, lego.plan);
  Cell cell;
  cell.ahead = 3;
  const Outcome out = run(t, cell);
  INFO(out.error);
  CHECK(out.complete);
  CHECK(std::find(out.statuses.begin(), out.statuses.end(), "waiting for station-1: 3 orders ahead") != out.statuses.end());
}

TEST_CASE("orchestrator: a waiting order takes the station that turns out reserved for it, and leaves the queue",
          "[twin][orchestration]") {
  const test::Planned lego(test::product("lego-tower/lego-tower.aml"));
  Twin t(lego.product, lego.plan);
  Cell cell;
  cell.ahead = 2;
  cell.turns_ours = "station-2";
  const Outcome out = run(t, cell);
  INFO(out.error);
  CHECK(out.complete);
  const auto at = [&](const std::string& what) { return std::find(out.order.begin(), out.order.end(), what) - out.order.begin(); };
  CHECK(at("RELEASE station-1") < at("AWARD station-2"));
  CHECK(at("AWARD station-2") < at("COMMAND grip"));
  CHECK(at("COMMAND grip") < static_cast<long>(out.order.size()));
}

TEST_CASE("orchestrator: no path in cell-sim for a part sends it back to sequence planning", "[twin][orchestration]") {
  const test::Planned cranfield(test::product("cranfield/cranfield.aml"));
  const twin::Plan& plan = cranfield.plan;
  REQUIRE(plan.complete);
  const std::string second = "o1/virtual/" + cranfield.product.product.parts()[plan.steps[1].part].name;
  Twin t(cranfield.product, plan);
  // cell-sim stops every move of the plan's second part while it would be second.
  Cell cell;
  cell.collide = [&](const Data& move, long placed) { return carries(move, second) && placed == 1; };
  const Outcome out = run(t, cell);
  INFO(out.error);
  CHECK(out.finished);
  CHECK(out.complete);
  // Every trajectory the planner had for it was tried in cell-sim first.
  CHECK(std::count(out.findings.begin(), out.findings.end(), "collision") ==
        static_cast<long>(plan.steps[1].failed.size() + 1));
  CHECK(std::count(out.findings.begin(), out.findings.end(), "backtrack") == 1);
  // The part came later instead; the rest of the plan is complete and validated.
  const auto& steps = t.orchestrator->plan().steps;
  REQUIRE(steps.size() == plan.steps.size());
  CHECK(steps[0].part == plan.steps[0].part);
  CHECK(steps[1].part != plan.steps[1].part);
  CHECK(std::find(out.spawned.begin(), out.spawned.end(), second) != out.spawned.end());
}

TEST_CASE("orchestrator: a twin taking up an order whose parts stand does not plan another order around them", "[twin][orchestration]") {
  const test::Planned cranfield(test::product("cranfield/cranfield.aml"));
  const twin::Plan& plan = cranfield.plan;
  const std::string first = "o1/" + cranfield.product.product.parts()[plan.steps[0].part].name;
  const std::string second = "o1/virtual/" + cranfield.product.product.parts()[plan.steps[1].part].name;
  twin::Resume resume;
  resume.attempt = 2;
  resume.station = "station-1";
  resume.placed = {first};
  resume.used = {first};
  Twin t(cranfield.product, plan, false, resume);
  Cell cell;  // as in the test above, which backtracks when nothing stands yet
  cell.collide = [&](const Data& move, long placed) { return carries(move, second) && placed == 1; };
  const Outcome out = run(t, cell);
  CHECK(out.finished);
  CHECK_FALSE(out.complete);
  CHECK(out.error.find("it is not planned otherwise around them") != std::string::npos);
  CHECK(std::count(out.findings.begin(), out.findings.end(), "backtrack") == 0);
}

TEST_CASE("orchestrator: a part that fits nowhere in cell-sim fails the order, with the reason", "[twin][orchestration]") {
  const test::Planned lego(test::product("lego-tower/lego-tower.aml"));
  Twin t(lego.product, lego.plan);
  Cell cell;
  cell.collide = [](const Data& move, long) { return carries(move, "o1/virtual/hanging"); };
  const Outcome out = run(t, cell);
  CHECK(out.finished);
  CHECK_FALSE(out.complete);
  CHECK(out.error.find("no collision-free path in cell-sim for hanging") != std::string::npos);
  CHECK(std::find(out.order.begin(), out.order.end(), "CFP host") == out.order.end());  // never booked a station
  CHECK(t.orchestrator->state() == twin::Phase::ended);
}

TEST_CASE("orchestrator: a request cell-sim answers busy goes again at the next tick, and the order goes on",
          "[twin][orchestration]") {
  const test::Planned lego(test::product("lego-tower/lego-tower.aml"));
  Twin t(lego.product, lego.plan);
  Cell cell;
  cell.ticks = 50;
  auto answered_busy = std::make_shared<std::set<std::string>>();
  cell.busy = [answered_busy](const Data& request) {  // the first two requests, once each
    const std::string id = get<std::string>(request, "request_id");
    if (answered_busy->size() >= 2 || answered_busy->count(id)) return false;
    answered_busy->insert(id);
    return true;
  };
  const Outcome out = run(t, cell);
  INFO(out.error);
  CHECK(out.finished);
  CHECK(out.complete);
  CHECK(answered_busy->size() == 2);
}

TEST_CASE("orchestrator: a cell-sim that stops answering in virtual assembly fails the order, naming the request",
          "[twin][orchestration]") {
  const test::Planned lego(test::product("lego-tower/lego-tower.aml"));
  Twin t(lego.product, lego.plan, false, {}, std::chrono::seconds(2), std::chrono::milliseconds(100));
  Cell cell;
  cell.ticks = 40;
  cell.tick_pause = std::chrono::milliseconds(10);
  auto moves = std::make_shared<int>(0);
  cell.silent = [moves](const Data& request) { return get<std::string>(request, "kind") == "move" && ++*moves == 3; };
  const Outcome out = run(t, cell);
  CHECK(out.finished);
  CHECK_FALSE(out.complete);
  CHECK_THAT(out.error, Catch::Contains("cell-sim did not answer request") && Catch::Contains("(move in virtual assembly)"));
  // Nothing physical began: no station was called for.
  CHECK(std::find(out.order.begin(), out.order.end(), "CFP host") == out.order.end());
}

TEST_CASE("orchestrator: the station whose place virtual assembly uses leaves in the middle of it, and the order goes on",
          "[twin][orchestration]") {
  const test::Planned lego(test::product("lego-tower/lego-tower.aml"));
  Twin t(lego.product, lego.plan);
  Cell cell;
  auto moves = std::make_shared<int>(0);
  cell.station_leaves = [moves](const fb::Event& e) {
    return e.name == "SIM" && get<std::string>(e.data, "kind") == "move" && ++*moves == 2;
  };
  const Outcome out = run(t, cell);
  INFO(out.error);
  CHECK(*moves > 2);
  CHECK(out.finished);
  CHECK(out.complete);
}

// Under load a station's capability may lapse a moment while an order books it. The arm was
// then called for with a hold of -1, every arm refused it ("the call's duration is not a number
// >= 0") and the order failed: once in sixty orders of cell_run_scale beside a build.
TEST_CASE("orchestrator: a station said gone a moment while it is booked: its arm is called for the hold known before",
          "[twin][orchestration]") {
  const test::Planned lego(test::product("lego-tower/lego-tower.aml"));
  Twin t(lego.product, lego.plan);
  Cell cell;
  auto awards = std::make_shared<int>(0);
  cell.station_leaves = [awards](const fb::Event& e) {
    return e.name == "AWARD" && get<std::string>(e.data, "resource_id") == "station-1" && ++*awards == 1;
  };
  const Outcome out = run(t, cell);
  INFO(out.error);
  CHECK(*awards >= 1);
  CHECK(out.complete);
  const auto call_for = [&](const std::string& operation) {
    const auto c = std::find_if(out.calls.begin(), out.calls.end(),
                                [&](const Data& d) { return get<std::string>(d, "operation") == operation; });
    return c == out.calls.end() ? -2.0 : get<double>(*c, "duration");
  };
  CHECK(call_for("host") > 0);
  CHECK(call_for("translate") == call_for("host"));
}

TEST_CASE("orchestrator: a failure in physical assembly cancels the fetches not yet delivered", "[twin][orchestration]") {
  const test::Planned lego(test::product("lego-tower/lego-tower.aml"));
  Twin t(lego.product, lego.plan);
  // The robot delivers the first two parts and queues the others; the arm cannot grip the second.
  int fetches = 0, grips = 0;
  std::vector<std::string> unanswered;
  Cell cell;
  cell.refuse = [&](const Data& c) -> std::string {
    const std::string& op = get<std::string>(c, "operation");
    if (op == "fetch" && ++fetches > 2) {
      unanswered.push_back(get<std::string>(c, "command_id"));
      return kAcceptOnly;
    }
    if (op == "grip" && ++grips == 2) return "gripper jammed";
    return "";
  };
  const Outcome out = run(t, cell);
  CHECK(out.finished);
  CHECK_FALSE(out.complete);
  CHECK(out.error.find("gripper jammed") != std::string::npos);
  std::sort(unanswered.begin(), unanswered.end());
  CHECK(out.canceled == unanswered);  // both in the order of their ids
  CHECK(unanswered.size() == lego.plan.steps.size() - 2);
}

TEST_CASE("orchestrator: an order the operator cancels in physical assembly fails with that reason, cancels its fetches and "
          "releases what it holds", "[twin][orchestration]") {
  const test::Planned lego(test::product("lego-tower/lego-tower.aml"));
  Twin t(lego.product, lego.plan);
  Cell cell;
  int fetches = 0, grips = 0;
  cell.refuse = [&](const Data& c) -> std::string {
    if (get<std::string>(c, "operation") == "fetch" && ++fetches > 2) return kAcceptOnly;  // the rest not yet delivered
    return "";
  };
  cell.stop_before = [&](const fb::Event& e) {
    return e.name == "COMMAND" && get<std::string>(e.data, "operation") == "grip" && ++grips == 2;
  };
  const Outcome out = run(t, cell);
  CHECK(out.finished);
  CHECK_FALSE(out.complete);
  CHECK(out.error == "cancelled by the operator (test)");
  REQUIRE_FALSE(out.statuses.empty());
  CHECK(out.statuses.back() == "cancelled by the operator (test)");
  CHECK(out.canceled.size() == lego.plan.steps.size() - 2);
  for (const char* held : {"RELEASE station-1", "RELEASE arm-1", "RELEASE mobile-robot-1"}) {
    CHECK(std::count(out.order.begin(), out.order.end(), held) == 1);
  }
}

TEST_CASE("orchestrator: the next fetch goes once the robot heard the last, so a resent one is not overtaken", "[twin][orchestration]") {
  // 40 orders on four stations: a fetch lost before the robot's reader matched was resent
  // after the next ones had gone, and the robot delivered the parts out of the plan's order.
  const test::Planned lego(test::product("lego-tower/lego-tower.aml"));
  Twin t(lego.product, lego.plan, false, {}, std::chrono::milliseconds(0));
  std::vector<std::string> sent;  // the fetches, as the robot got them
  bool lost = false;
  Cell cell;
  cell.ticks = 50;
  cell.refuse = [&](const Data& c) -> std::string {
    if (get<std::string>(c, "operation") != "fetch") return "";
    sent.push_back(get<std::string>(c, "command_id"));
    if (sent.back() == "o1/2/fetch" && !lost) {
      lost = true;
      return kNoAnswer;
    }
    return "";
  };
  const Outcome out = run(t, cell);
  CHECK(out.complete);
  INFO(fb::join_names(sent));
  REQUIRE(sent.size() == lego.plan.steps.size() + 1);  // one of them twice
  CHECK(sent[1] == "o1/2/fetch");
  CHECK(sent[2] == "o1/2/fetch");  // resent before any later one went
  for (std::size_t i = 3; i < sent.size(); ++i) CHECK(sent[i] == "o1/" + std::to_string(i) + "/fetch");
}

TEST_CASE("orchestrator: an order for a quote assembles virtually, asks for bids, and takes nothing", "[twin][orchestration][quote]") {
  const test::Planned cranfield(test::product("cranfield/cranfield.aml"));
  Twin t(cranfield.product, cranfield.plan, true);
  const Outcome out = run(t, Cell{});
  INFO(out.error);
  CHECK(out.complete);
  CHECK(std::count(out.order.begin(), out.order.end(), "SIM set_static") == static_cast<long>(cranfield.plan.steps.size()));
  CHECK(std::none_of(out.order.begin(), out.order.end(), [](const std::string& o) { return o.rfind("AWARD", 0) == 0; }));
  CHECK(std::none_of(out.order.begin(), out.order.end(), [](const std::string& s) { return s.rfind("COMMAND", 0) == 0; }));
  CHECK(std::find(out.order.begin(), out.order.end(), "CFP host") != out.order.end());
  CHECK(std::find(out.order.begin(), out.order.end(), "CFP fetch") != out.order.end());
  REQUIRE(out.quote);
  const Data& q = *out.quote;
  CHECK(get<std::string>(q, "station") == "station-1");
  CHECK(get<std::string>(q, "robot") == "mobile-robot-1");
  // The stand-in cell's robot stands at the station's place and drives to the one dock of
  // all (0.6 m at 0.25 m/s) once: the arm waits 2.4 s for the first part, then works as long
  // as the order would hold the station; the twin knows no real-time factor here, so its
  // messages take no time.
  CHECK(get<double>(q, "wait") == 0);
  CHECK(get<double>(q, "robot_s") == Approx(2.4));
  const double hold = t.orchestrator->hold_at("station-1");
  CHECK(hold > 10);
  CHECK(get<double>(q, "makespan") == Approx(2.4 + hold));
}

TEST_CASE("orchestrator: a quote nobody can bid on ends with every refusal's reason", "[twin][orchestration][quote]") {
  const test::Planned lego(test::product("lego-tower/lego-tower.aml"));
  Twin t(lego.product, lego.plan, true);
  Cell cell;
  cell.refuse_call = [](const Data& call) {
    return get<std::string>(call, "part_type") == "Brick2x2" ? std::string("buffer-1 has 0 Brick2x2 free, not 4") : "";
  };
  const Outcome out = run(t, cell);
  CHECK(out.finished);
  CHECK_FALSE(out.quote);
  CHECK(out.error.find("buffer-1 has 0 Brick2x2 free") != std::string::npos);
  CHECK(std::none_of(out.order.begin(), out.order.end(), [](const std::string& o) { return o.rfind("AWARD", 0) == 0; }));
}

TEST_CASE("orchestrator: bids to host the order are weighed by its model at each station, so the faster arm wins",
          "[twin][orchestration][quote]") {
  const test::Planned cranfield(test::product("cranfield/cranfield.aml"));
  Twin t(cranfield.product, cranfield.plan);
  const auto place = [&t](const std::string& id, const std::string& kind, double z, double speed) {
    t.send("orchestrator", "CAPABILITY",
           {{"resource_id", id}, {"kind", kind}, {"operations", std::string()}, {"position", fb::Numbers{0, 0, z}},
            {"dock", fb::Numbers{0.6, 0, z}}, {"speed", speed}, {"angular_speed", 1.0}, {"reserved_by", std::string()},
            {"waiting", std::string()}});
  };
  place("station-1", "station", 0, 0);
  place("arm-1", "arm", 0, 0.1);
  place("station-2", "station", 3, 0);
  place("arm-2", "arm", 3, 0.4);
  const double slow = t.orchestrator->hold_at("station-1"), fast = t.orchestrator->hold_at("station-2");
  CHECK(slow == Approx(4 * fast).epsilon(0.05));  // the same work at a quarter of the speed (turns aside)
  CHECK(t.orchestrator->hold_at("station-3") < 0);  // not heard of

  // Both offer the same: the order's own estimate, from now. The faster arm finishes first,
  // unless its queue holds the order up longer than the slower arm takes.
  const twin::ModelledFinish finish(*t.orchestrator);
  const auto bid = [](const std::string& station, double start) { return fb::Bid{station, start, 1.0, 0, "host"}; };
  CHECK(finish.cost(bid("station-2", 0)) < finish.cost(bid("station-1", 0)));
  CHECK(finish.cost(bid("station-2", slow)) > finish.cost(bid("station-1", 0)));
  CHECK(finish.cost(bid("station-3", 5)) == 6);  // not heard of: its bid's duration
  CHECK(finish.cost(fb::Bid{"mobile-robot-1", 2, 3, 0, "fetch"}) == 5);
}
