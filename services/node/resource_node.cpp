#include "services/node/resource_node.hpp"

#include <malloc.h>

#include <atomic>
#include <mutex>
#include <thread>

#include "capabilitiesPubSubTypes.h"
#include "commandsPubSubTypes.h"
#include "negotiationPubSubTypes.h"
#include "rosterPubSubTypes.h"
#include "services/blocks/action_block.hpp"
#include "services/dds/conversions.hpp"
#include "services/dds/order_watch.hpp"
#include "services/dds/service_blocks.hpp"
#include "services/node/restart_reason.hpp"
#include "services/node/sim_requests.hpp"
#include "services/state/cell_store.hpp"
#include "simulationPubSubTypes.h"

namespace services {
namespace {

using dds::TopicKind;
template <class T, class P>
using Sub = dds::SubscribeBlock<T, P>;
template <class T, class P>
using Pub = dds::PublishBlock<T, P>;

const std::pair<const char*, cell::CommandState> kLifecycleOutputs[] = {
    {"ACCEPTED", cell::ACCEPTED}, {"EXECUTING", cell::EXECUTING}, {"SUCCEEDED", cell::SUCCEEDED},
    {"ABORTED", cell::ABORTED},   {"REJECTED", cell::REJECTED},   {"CANCELING", cell::CANCELING},
    {"CANCELED", cell::CANCELED}};

bool is_final(cell::CommandState s) {
  return s == cell::SUCCEEDED || s == cell::ABORTED || s == cell::CANCELED || s == cell::REJECTED;
}

// Publishes the capability once the events queued before are through: a command's events go
// out first (a commander waits for them, not for the capability), and a command done at
// once (a buffer's give) leaves nothing to say about busy or idle.
//   CHECK: publish if busy, idle or the queue changed;  CHANGED: publish (a stock changed)
class CapabilityRefresh : public fb::FunctionBlock {
 public:
  CapabilityRefresh(std::string name, std::function<void(bool force)> refresh)
      : FunctionBlock(std::move(name)), refresh_(std::move(refresh)) {
    declare_input("CHECK");
    declare_input("CHANGED");
    declare_input("LATER");
  }
  void receive(const fb::Event& e) override {
    if (e.name == "LATER") {
      pending_ = false;
      return refresh();
    }
    force_ |= e.name == "CHANGED";
    if (pending_) return;
    try {
      post_to_self("LATER");
      pending_ = true;
    } catch (const fb::EventQueueOverflow&) {
      // A burst filled the queue: the next event through here, or idle() once the queue is
      // empty, refreshes. (Before, the LATER never posted left it pending for good, and the
      // capability stopped saying what the resource refused.)
      missed_ = true;
    }
  }
  void idle() override {
    if (missed_ && !pending_) refresh();
  }

 private:
  void refresh() {
    refresh_(force_);
    force_ = missed_ = false;
  }
  std::function<void(bool)> refresh_;
  bool pending_ = false, force_ = false, missed_ = false;
};


}  // namespace

struct ResourceNode::Impl {
  fb::Resource& resource;
  dds::ParticipantPtr participant;
  NodeConfig config;
  fb::DeviceBlock& device;
  fb::Contractor* contractor = nullptr;
  std::function<void(cell::Capability&)> describe;
  std::unique_ptr<state::CellStore> store;
  std::string recovered;  // what the device did with what its predecessor process held
  std::chrono::steady_clock::time_point last_check;
  std::chrono::steady_clock::time_point last_tick;
  dds::SimClock clock;
  std::unique_ptr<dds::Writer<cell::Capability, cell::CapabilityPubSubType>> capabilities;
  // Answers to commands the resource's queue had no room for, written on the listener thread.
  std::unique_ptr<dds::Outbox<cell::CommandEvent, cell::CommandEventPubSubType>> overflow_answers;
  std::atomic<std::size_t> overflowed{0};
  std::size_t overflowed_published = 0;  // resource thread only
  std::size_t refused_at_trim = 0;        // refusals counted at the last malloc_trim
  std::mutex refusal_mutex;
  std::string last_overflow;
  std::vector<std::function<void()>> starters;
  Pub<cell::SimRequest, cell::SimRequestPubSubType>* sim_requests = nullptr;
  fb::CommandLifecycle* lifecycle = nullptr;
  std::string ping_id;
  bool sim_answers = false;
  bool busy = false;  // as last published
  std::size_t queued_published = 0;

  Impl(fb::Resource& r, dds::ParticipantPtr p, NodeConfig c, fb::DeviceBlock& d)
      : resource(r), participant(p), config(std::move(c)), device(d), clock(p) {}

  template <class T, class P>
  Sub<T, P>& subscribe(const std::string& name, const std::string& topic, TopicKind kind,
                       typename Sub<T, P>::ToData to_data, const dds::QosSettings& settings = {}) {
    auto& block =
        resource.add(std::make_unique<Sub<T, P>>(name, participant, topic, kind, std::move(to_data), settings));
    starters.push_back([&block] { block.start(); });
    return block;
  }
  template <class T, class P>
  void publish(const std::string& name, const std::string& topic, typename Pub<T, P>::ToSample to_sample) {
    // What a resource writes about itself goes in its partition (dds::owned_topic).
    const dds::QosSettings settings =
        dds::own_events_qos(dds::owned_topic(topic) ? dds::owned_by({config.id}) : dds::QosSettings{});
    resource.add(std::make_unique<Pub<T, P>>(name, participant, topic, TopicKind::events, std::move(to_sample), settings));
  }

  void publish_capability() {
    cell::Capability c;
    c.resource_id(config.id);
    c.kind(config.kind);
    std::set<std::string> operations = device.operations();
    operations.insert(config.offers.begin(), config.offers.end());
    c.operations(cell::Ids(operations.begin(), operations.end()));
    c.position(dds::vec3(config.position[0], config.position[1], config.position[2]));
    c.dock(dds::vec3(config.dock[0], config.dock[1], config.dock[2]));
    c.reach(config.reach);
    c.speed(config.speed);
    c.angular_speed(config.angular_speed);
    c.reserved_by(contractor->reserved_by());
    const std::vector<std::string> waiting = contractor->waiting();
    c.waiting(cell::Ids(waiting.begin(), waiting.end()));
    c.queued_commands(static_cast<int32_t>(lifecycle->queued()));
    c.busy(busy);
    overflowed_published = overflowed;
    c.refused_commands(static_cast<int32_t>(device.refused() + overflowed_published));
    c.out_of_service(contractor->out_of_service());
    {
      std::lock_guard<std::mutex> lock(refusal_mutex);
      const std::string& last = last_overflow.empty() ? device.last_refusal() : last_overflow;
      c.last_refusal(last.substr(0, cell::Text::max_size - 1));
      last_overflow.clear();
    }
    if (describe) describe(c);
    capabilities->write(c);
  }

  // Takes up what the process before it had taken on, but for orders that ended meanwhile;
  // from now on every change is stored before it is confirmed.
  void keep_bookings() {
    std::set<std::string> ended;
    for (const auto& o : store->orders()) {
      if (o.ended()) ended.insert(o.order);
    }
    std::vector<fb::Contractor::Booking> restored;
    std::string orders;
    for (const auto& b : store->bookings(config.id)) {
      if (ended.count(b.order)) continue;
      restored.push_back({b.order, std::set<std::string>(b.calls.begin(), b.calls.end()), b.duration, b.holds});
      orders += (orders.empty() ? "" : ", ") + b.order + (b.holds ? " (holds it)" : "");
    }
    contractor->restore(restored);
    if (!orders.empty()) store->journal(config.id, "bookings restored", "", orders);
    const auto save = [this](const std::vector<fb::Contractor::Booking>& bookings) {
      std::vector<state::BookingRecord> records;
      for (const auto& b : bookings) records.push_back({b.order, {b.calls.begin(), b.calls.end()}, b.duration, b.holds});
      store->set_bookings(config.id, records);
    };
    save(contractor->bookings());
    contractor->persist_with(save);
  }

  // The commands the process before this one had taken on when it ended: ABORTED, with why.
  void answer_interrupted() {
    const auto interrupted = store->take_interrupted(config.id);
    if (interrupted.empty()) return;
    // An event nobody hears is lost: the readers already there (the commanders' among them)
    // are given time to match.
    overflow_answers->writer().wait_for_settled_readers(std::chrono::milliseconds(500), std::chrono::seconds(3));
    for (const auto& c : interrupted) {
      const bool concerned = !c.part.empty() && recovered.find(c.part) != std::string::npos;
      const std::string reason = fb::restarted_reason(config.id) + (concerned ? "; " + recovered : "");
      store->journal(config.id, "aborted", c.order, c.command_id + ": " + reason);
      cell::CommandEvent e;
      e.command_id(c.command_id);
      e.resource_id(config.id);
      e.order_id(c.order);
      e.operation(c.operation);
      e.part(c.part);
      e.state(cell::ABORTED);
      e.reason(reason.substr(0, cell::Text::max_size - 1));
      e.sim_time(clock.now());
      // The same command sent again (its sender heard nothing) gets this answer again, not a
      // second execution.
      device.ended(c.command_id, {{"command_id", c.command_id}, {"resource_id", config.id}, {"order_id", c.order},
                                  {"operation", c.operation}, {"part", c.part}, {"state", std::string("aborted")},
                                  {"reason", reason}, {"sim_time", e.sim_time()}});
      overflow_answers->write(e);
    }
  }

  cell::CommandEvent event_of(cell::CommandState state, const fb::Data& d) {
    const std::string& id = fb::get<std::string>(d, "command_id");
    const fb::Data& known = device.command(id);
    const fb::Data& command = known.empty() ? d : known;  // a refused command was never the device's
    cell::CommandEvent e;
    e.command_id(id);
    e.resource_id(config.id);
    e.order_id(fb::get_or<std::string>(command, "order_id", ""));
    e.operation(fb::get_or<std::string>(command, "operation", ""));
    e.part(fb::get_or<std::string>(command, "part", ""));
    e.state(state);
    e.progress(fb::get_or<double>(d, "progress", state == cell::SUCCEEDED ? 1.0 : 0.0));
    e.reason(fb::get_or<std::string>(d, "reason", ""));
    e.distance(fb::get_or<double>(d, "distance", 0));
    e.duration(fb::get_or<double>(d, "duration", 0));
    clock.observe(fb::get_or<double>(command, "sim_time", 0));
    if (const auto t = d.find("sim_time"); t != d.end()) clock.observe(std::get<double>(t->second));
    e.sim_time(d.count("sim_time") ? fb::get<double>(d, "sim_time") : clock.now());
    if (store && !known.empty()) {
      if (state == cell::ACCEPTED) {
        store->command_taken({config.id, id, e.order_id().to_string(), e.operation().to_string(), e.part().to_string()});
      } else if (is_final(state)) {
        store->command_ended(config.id, id);
      }
    }
    if (is_final(state) && !known.empty()) {
      fb::Data last = d;
      last["state"] = std::string(dds::state_name(state));
      last["sim_time"] = e.sim_time();
      device.ended(id, last);
    }
    return e;
  }

  // After an event is out: the capability again if the resource turned busy or idle, or its
  // queue changed (not before: the event is what a commander waits for).
  void refresh_capability(bool force) {
    const std::size_t queued = lifecycle->queued();
    if (!force && (lifecycle->state() != "IDLE") == busy && queued == queued_published) return;
    busy = lifecycle->state() != "IDLE";
    queued_published = queued;
    publish_capability();
  }
};

ResourceNode::ResourceNode(fb::Resource& resource, dds::ParticipantPtr participant, NodeConfig config,
                           fb::DeviceBlock& device, fb::Contractor::EstimateFn estimate,
                           std::function<void(cell::Capability&)> describe)
    : impl_(std::make_unique<Impl>(resource, participant, std::move(config), device)) {
  Impl& n = *impl_;
  n.describe = std::move(describe);
  if (!n.config.state_dir.empty()) {
    n.store = std::make_unique<state::CellStore>(n.config.state_dir);
    n.recovered = device.keep_state_in(*n.store);
    if (!n.recovered.empty()) n.store->journal(n.config.id, "recovered", "", n.recovered);
  }
  dds::QosSettings qos;
  qos.liveliness_lease_s = n.config.liveliness_lease_s;
  n.capabilities = std::make_unique<dds::Writer<cell::Capability, cell::CapabilityPubSubType>>(
      participant, "cell/capabilities", TopicKind::state, dds::owned_by({n.config.id}, qos));

  // Commands and their life cycle.
  const std::string dev = device.name();
  n.lifecycle = &resource.add(std::make_unique<fb::CommandLifecycle>("lifecycle", n.config.when_busy));
  const std::string me = n.config.id;
  device.set_bounds(n.config.bounds);
  device.authorize_with([&n](const fb::Data& c) {
    return n.contractor->refusal(fb::get_or<std::string>(c, "order_id", ""), fb::get_or<std::string>(c, "award", ""));
  });
  auto& commands = n.subscribe<cell::Command, cell::CommandPubSubType>(
      "commands", dds::command_topic(me), TopicKind::events,
      [me](const cell::Command& c) { return c.resource_id().to_string() == me ? dds::to_data(c) : fb::Data{}; },
      dds::command_qos());
  if (n.config.commanded_by_destination) commands.written_by([](const cell::Command& c) { return c.destination().to_string(); });
  n.overflow_answers = std::make_unique<dds::Outbox<cell::CommandEvent, cell::CommandEventPubSubType>>(
      participant, "cell/command_events", TopicKind::events, dds::own_events_qos(dds::owned_by({n.config.id})));
  commands.on_refused([&n](const cell::Command& c, const std::string& why) {
    cell::CommandEvent e;
    e.command_id(c.command_id());
    e.resource_id(n.config.id);
    e.order_id(c.order_id());
    e.operation(c.operation());
    e.part(c.part());
    e.state(cell::REJECTED);
    e.reason(n.config.id + ": " + why);
    e.sim_time(n.clock.now());
    {
      std::lock_guard<std::mutex> lock(n.refusal_mutex);
      n.last_overflow = c.order_id().to_string() + " " + c.command_id().to_string() + ": " + why;
    }
    ++n.overflowed;  // counted before it is answered: whoever hears the answer finds it counted
    n.overflow_answers->write(e);
  });
  resource.connect("commands", "IND", dev, "COMMAND");
  // Refusals counted on the listener thread while the queue was full, published once it is quiet.
  resource.on_idle([&n] {
    n.overflow_answers->flush();
    if (n.overflowed != n.overflowed_published) n.publish_capability();
    // Quiet after refused commands: what their events and samples took on the heap is given
    // back to the system, at every quiet moment after one (a flood that a loaded machine slows
    // down has quiet moments in its middle). What DDS keeps in its writers' histories is not
    // heap it frees: that is bounded by dds::own_events_qos.
    const std::size_t refused = n.device.refused() + n.overflowed;
    if (refused != n.refused_at_trim) {
      n.refused_at_trim = refused;
      ::malloc_trim(0);
    }
    // Now and then: has a suspended order ended, or waited too long for its twin?
    const auto now = std::chrono::steady_clock::now();
    if (n.store && now - n.last_check > std::chrono::seconds(1)) {
      n.last_check = now;
      n.resource.post("order_watch", "CHECK");
    }
    // A device that waits on others (a robot on a buffer's answer) looks again now and then.
    if (n.device.has_input("TICK") && now - n.last_tick > std::chrono::milliseconds(500)) {
      n.last_tick = now;
      n.resource.post(n.device.name(), "TICK");
    }
  });
  n.subscribe<cell::CancelRequest, cell::CancelRequestPubSubType>(
      "cancels", "cell/cancel_requests", TopicKind::events,
      [](const cell::CancelRequest& c) {
        return fb::Data{{"command_id", c.command_id().to_string()}, {"order_id", c.order_id().to_string()}};
      });
  resource.connect("cancels", "IND", "lifecycle", "CANCEL");
  resource.connect(dev, "ACCEPT", "lifecycle", "COMMAND");
  resource.connect("lifecycle", "START", dev, "START");
  for (const char* e : {"PROGRESS", "DONE", "FAIL"}) resource.connect(dev, e, "lifecycle", e);
  n.publish<cell::CommandEvent, cell::CommandEventPubSubType>("event_repeat", "cell/command_events",
                                                             [](const fb::Data& d) { return dds::to_command_event(d); });
  resource.connect(dev, "REPEAT", "event_repeat", "REQ");
  resource.add(std::make_unique<CapabilityRefresh>("capability_refresh", [&n](bool force) { n.refresh_capability(force); }));
  for (const auto& [output, state] : kLifecycleOutputs) {
    const std::string name = std::string("event_") + output;
    const cell::CommandState s = state;
    n.publish<cell::CommandEvent, cell::CommandEventPubSubType>(
        name, "cell/command_events", [&n, s](const fb::Data& d) { return n.event_of(s, d); });
    resource.connect("lifecycle", output, name, "REQ");
    resource.connect(name, "CNF", "capability_refresh", "CHECK");
  }
  resource.connect(dev, "REFUSE", "event_REJECTED", "REQ");

  // The contract net.
  n.contractor = &resource.add(std::make_unique<fb::Contractor>("contractor", n.config.id, n.config.offers, n.config.exclusive,
                                                                std::move(estimate), [&n] { return n.clock.now(); }));
  if (n.store) n.keep_bookings();
  n.subscribe<cell::CallForProposals, cell::CallForProposalsPubSubType>(
      "calls", "cell/negotiation/calls", TopicKind::events, [](const cell::CallForProposals& c) { return dds::to_data(c); });
  n.subscribe<cell::Award, cell::AwardPubSubType>("awards", "cell/negotiation/awards", TopicKind::events,
                                                  [](const cell::Award& a) { return dds::to_data(a); });
  n.subscribe<cell::Release, cell::ReleasePubSubType>("releases", "cell/negotiation/releases", TopicKind::events,
                                                      [](const cell::Release& r) { return dds::to_data(r); });
  // With the cell's state, an order whose twin died waits for the twin the cell starts again.
  fb::OrderWatch::Resumable resumable;
  if (n.store) resumable = [&n](const std::string& order) { return n.store->awaits_twin(order); };
  auto& orders = dds::watch_orders(resource, participant, std::move(resumable));
  n.starters.push_back([&orders] { orders.start(); });
  resource.connect("calls", "IND", "contractor", "CFP");
  resource.connect("awards", "IND", "contractor", "AWARD");
  resource.connect("releases", "IND", "contractor", "RELEASE");
  resource.connect("lifecycle", "IDLE", "contractor", "IDLE");
  resource.connect("order_watch", "ENDED", "contractor", "ORDER_ENDED");
  resource.connect("order_watch", "ENDED", dev, "ORDER_ENDED");
  resource.connect("order_watch", "ACTIVE", dev, "ORDER_ACTIVE");
  if (device.has_input("AWARDED")) resource.connect("contractor", "AWARDED", dev, "AWARDED");
  const std::string id = n.config.id;
  n.publish<cell::Proposal, cell::ProposalPubSubType>("proposals", "cell/negotiation/proposals", [id](fb::Data d) {
    d["resource_id"] = id;
    return dds::to_proposal(d);
  });
  n.publish<cell::AwardReply, cell::AwardReplyPubSubType>("award_replies", "cell/negotiation/replies", [id](fb::Data d) {
    d["resource_id"] = id;
    return dds::to_award_reply(d);
  });
  resource.connect("contractor", "PROPOSE", "proposals", "REQ");
  resource.connect("contractor", "REPLY", "award_replies", "REQ");
  resource.add(std::make_unique<fb::ActionBlock>("capability", [this](const fb::Data&) { publish_capability(); }));
  resource.connect("contractor", "RESERVED", "capability", "REQ");
  // The operator's word on this resource, in the cell's roster: out of service, or back.
  n.subscribe<cell::CellRoster, cell::CellRosterPubSubType>(
      "roster", "cell/roster", TopicKind::state, [id](const cell::CellRoster& roster) {
        for (const auto& e : roster.resources()) {
          if (e.resource_id().to_string() == id) return fb::Data{{"out_of_service", e.out_of_service().to_string()}};
        }
        return fb::Data{};  // a roster that does not name it
      });
  resource.connect("roster", "IND", "contractor", "SERVICE");
  resource.connect("roster", "IND", "capability", "REQ");
  if (device.has_output("CAPABILITY")) resource.connect(dev, "CAPABILITY", "capability_refresh", "CHANGED");
  resource.connect(dev, "REFUSE", "capability_refresh", "CHANGED");

  // cell-sim, for devices that move things.
  if (device.has_output("SIM")) {
    n.publish<cell::SimRequest, cell::SimRequestPubSubType>("sim_requests", "cell/sim/requests",
                                                            [](const fb::Data& d) { return dds::to_sim_request(d); });
    n.sim_requests = &dynamic_cast<Pub<cell::SimRequest, cell::SimRequestPubSubType>&>(resource.block("sim_requests"));
    // Only this resource's replies (a device's, or the node's pings).
    const std::string me = n.config.id;
    n.subscribe<cell::SimReply, cell::SimReplyPubSubType>(
        "sim_replies", "cell/sim/replies", TopicKind::events, [me](const cell::SimReply& r) {
          return r.requester() == me || r.requester() == me + "/node" ? dds::to_data(r) : fb::Data{};
        });
    resource.connect(dev, "SIM", "sim_requests", "REQ");
    resource.connect("sim_replies", "IND", dev, "SIM_REPLY");
    resource.add(std::make_unique<fb::ActionBlock>("sim_ping", [&n](const fb::Data& reply) {
      if (fb::get<std::string>(reply, "request_id") == n.ping_id) n.sim_answers = true;
    }));
    resource.connect("sim_replies", "IND", "sim_ping", "REQ");
  }
}

ResourceNode::~ResourceNode() { impl_->resource.on_idle({}); }

void ResourceNode::start(std::chrono::milliseconds wait_for_sim, const std::atomic<bool>* running) {
  Impl& n = *impl_;
  const auto stopped = [running] { return running && !*running; };
  const auto gone = [&] {
    return std::runtime_error("cell-sim did not answer within " + std::to_string(wait_for_sim.count() / 1000) +
                              " s on this domain");
  };
  // Requests are events, lost if nobody listens yet: a device that moves things needs cell-sim.
  const auto deadline = std::chrono::steady_clock::now() + wait_for_sim;
  while (n.sim_requests && !n.sim_requests->writer().wait_for_readers(1, std::chrono::milliseconds(100))) {
    if (stopped()) return;
    if (std::chrono::steady_clock::now() > deadline) throw gone();
  }
  publish_capability();
  for (auto& start : n.starters) start();
  if (n.store) n.answer_interrupted();
  if (!n.sim_requests) return;
  // And its replies must reach this process: DDS matches each pair of endpoints on its own,
  // and a device whose first reply was lost (its spawn) never became ready. Pinged until it
  // answers, on this thread, before the resource's own thread runs.
  fb::SimRequests pings(n.config.id + "/node");
  for (int round = 0; !n.sim_answers; ++round) {
    if (stopped()) return;
    if (std::chrono::steady_clock::now() > deadline) throw gone();
    if (round % 10 == 0) {
      const fb::Data ping = pings.ping();
      n.ping_id = fb::get<std::string>(ping, "request_id");
      n.resource.post("sim_requests", "REQ", ping);
    }
    n.resource.run_until_idle();
    if (!n.sim_answers) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

dds::SimClock& ResourceNode::clock() { return impl_->clock; }

void ResourceNode::publish_capability() { impl_->publish_capability(); }

}  // namespace services
