// cell-sim: the cell's one shared Bullet world, served over DDS. Requests on
// cell/sim/requests (spawn, remove, set_static, set_movable, move) are answered on
// cell/sim/replies; moves take simulated time from their speeds and end at the first
// collision. The sim clock goes out on cell/clock.
//   cell-sim --domain 42 --real-time-factor 20

#include <atomic>
#include <iostream>

#include <CLI/CLI.hpp>

#include "services/dds/cli_options.hpp"
#include "services/dds/conversions.hpp"
#include "services/dds/order_watch.hpp"
#include "services/dds/service_blocks.hpp"
#include "sim/cell_sim/world_block.hpp"
#include "capabilitiesPubSubTypes.h"
#include "negotiationPubSubTypes.h"
#include "simulationPubSubTypes.h"
#include "services/node/run.hpp"
#include "services/state/cell_store.hpp"

int main(int argc, char** argv) {
  CLI::App app{"cell-sim: the shared simulation of the assembly cell"};
  dds::ParticipantSettings settings;
  double factor = 1.0;
  bool verbose = false;
  bool all_interfaces = false;
  std::vector<double> bounds;
  dds::add_dds_options(app, settings, all_interfaces);
  dds::add_bounds_option(app, bounds);
  app.add_option("--real-time-factor", factor, "Sim seconds per wall second")->check(CLI::PositiveNumber);
  app.add_flag("--verbose", verbose, "Print every request and reply");
  std::string state_dir;
  dds::add_state_option(app, state_dir);
  CLI11_PARSE(app, argc, argv);
  dds::apply_interfaces(settings, all_interfaces);
  const std::atomic<bool>& running = services::run_until_signalled();
  try {
    auto participant = dds::make_participant("cell-sim", settings);
    // Before the resource: its reader's listener may answer through it until the resource is gone.
    dds::Outbox<cell::SimReply, cell::SimReplyPubSubType> refusals(participant, "cell/sim/replies", dds::TopicKind::events);
    // Every twin in virtual assembly spawns its product's parts at once: 40 twins of the
    // Cranfield product and the Lego tower filled 1024 events (a clean-clone CI rehearsal's
    // scale test, beside other load). Four times that; a request past it is answered "busy"
    // (below). Not more: a queued move may hold 2048 waypoints.
    fb::Resource resource("cell-sim", 4096);
    resource.add(std::make_unique<sim::WorldBlock>("world", factor, dds::apply_bounds(bounds)));
    auto& requests = resource.add(std::make_unique<dds::SubscribeBlock<cell::SimRequest, cell::SimRequestPubSubType>>(
        "requests", participant, "cell/sim/requests", dds::TopicKind::events,
        [verbose](const cell::SimRequest& r) {
          if (verbose) std::cout << "request " << r.request_id() << " " << r.kind() << " " << r.body_id() << std::endl;
          return dds::to_data(r);
        }));
    resource.add(std::make_unique<dds::PublishBlock<cell::SimReply, cell::SimReplyPubSubType>>(
        "replies", participant, "cell/sim/replies", dds::TopicKind::events,
        [verbose](const fb::Data& d) {
          cell::SimReply reply = dds::to_sim_reply(d);
          if (verbose) std::cout << "reply " << reply.request_id() << (reply.ok() ? " ok " : " refused ") << reply.error() << std::endl;
          return reply;
        }));
    resource.add(std::make_unique<dds::PublishBlock<cell::Clock, cell::ClockPubSubType>>(
        "clock", participant, "cell/clock", dds::TopicKind::state, [](const fb::Data& d) {
          cell::Clock c;
          c.sim_time(fb::get<double>(d, "sim_time"));
          c.real_time_factor(fb::get<double>(d, "real_time_factor"));
          return c;
        }));
    // Who hired whom: a resource may move an order's parts while the order has hired it.
    auto& hires = resource.add(std::make_unique<dds::SubscribeBlock<cell::AwardReply, cell::AwardReplyPubSubType>>(
        "hires", participant, "cell/negotiation/replies", dds::TopicKind::events, [](const cell::AwardReply& r) {
          if (!r.confirmed()) return fb::Data{};
          return fb::Data{{"resource_id", r.resource_id().to_string()}, {"order_id", r.order_id().to_string()}};
        }));
    resource.connect("hires", "IND", "world", "HIRED");
    // A request that finds the queue full is answered so, not dropped: its requester would
    // wait its whole timeout and blame a cell-sim that is not there.
    requests.on_refused([&refusals](const cell::SimRequest& r, const std::string& why) {
      cell::SimReply reply;
      reply.request_id(r.request_id());
      reply.requester(r.requester());
      reply.ok(false);
      reply.error("busy: cell-sim's event queue is " + why + "; ask again");
      refusals.write(reply);
    });
    resource.on_idle([&refusals] { refusals.flush(); });
    // With the cell's state, the bodies of an order whose twin died wait for the next twin.
    std::unique_ptr<state::CellStore> store;
    if (!state_dir.empty()) store = std::make_unique<state::CellStore>(state_dir);
    fb::OrderWatch::Resumable resumable;
    if (store) resumable = [&store](const std::string& order) { return store->awaits_twin(order); };
    auto& orders = dds::watch_orders(resource, participant, std::move(resumable));
    resource.connect("order_watch", "ENDED", "world", "ORDER_ENDED");
    resource.connect("requests", "IND", "world", "REQUEST");
    resource.connect("world", "REPLY", "replies", "REQ");
    resource.connect("world", "CLOCK", "clock", "REQ");
    // Its own line in the cell's status: requests it refused, and the last one's requester and reason.
    resource.add(std::make_unique<dds::PublishBlock<cell::Capability, cell::CapabilityPubSubType>>(
        "status", participant, "cell/capabilities", dds::TopicKind::state, [](const fb::Data& d) {
          cell::Capability c;
          c.resource_id("cell-sim");
          c.kind("simulation");
          c.refused_commands(static_cast<int32_t>(fb::get_or<std::int64_t>(d, "refused", 0)));
          c.last_refusal(fb::get_or<std::string>(d, "last_refusal", "").substr(0, cell::Text::max_size - 1));
          return c;
        },
        dds::owned_by({"cell-sim"})));
    resource.connect("world", "REFUSED", "status", "REQ");
    resource.post("status", "REQ");
    requests.start();
    hires.start();
    orders.start();
    std::cout << "cell-sim ready on domain " << settings.domain_id << ", real-time factor " << factor << std::endl;
    auto last_check = std::chrono::steady_clock::now();
    // Its own periodic events: a queue full of requests skips one (the next comes soon), and
    // never ends the process (one did so, and the whole cell restarted).
    const auto post_own = [&resource](const char* block, const char* input) {
      try {
        resource.post(block, input);
      } catch (const fb::EventQueueOverflow&) {
      }
    };
    services::Heartbeat heartbeat;  // cellctl up restarts a cell-sim whose loop stops turning
    while (running) {
      heartbeat.beat();
      if (!resource.wait_and_run_one(std::chrono::milliseconds(1))) post_own("world", "TICK");
      if (store && std::chrono::steady_clock::now() - last_check > std::chrono::seconds(1)) {
        last_check = std::chrono::steady_clock::now();
        post_own("order_watch", "CHECK");
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "error: cell-sim: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
