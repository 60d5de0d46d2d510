// twin: the digital twin of one order. Reads the product description, plans the assembly,
// then orchestrates the cell over DDS (OrderOrchestrator): negotiation, virtual assembly in
// cell-sim, physical assembly. Publishes its status while it lives (a twin that dies is
// noticed by the resources it reserved) and writes the plan and the animation.
//   twin --domain 42 --order o1 --product deploy/products/cranfield/cranfield.aml --out out/o1
// With --quote it assembles virtually only and writes quote.json (docs/quotes.md).
// With --standby it joins the cell first and reads the order's options from standard input,
// one per line, ended by an empty line (cellctl up's standby twins: docs/order-desk.md).
// Exit codes: 0 assembled (or quoted, feasible or not), 1 the order failed, 2 bad input.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <atomic>
#include <thread>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include <poll.h>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include "capabilitiesPubSubTypes.h"
#include "rosterPubSubTypes.h"
#include "commandsPubSubTypes.h"
#include "negotiationPubSubTypes.h"
#include "ordersPubSubTypes.h"
#include "services/blocks/action_block.hpp"
#include "services/dds/cli_options.hpp"
#include "services/dds/conversions.hpp"
#include "services/dds/service_blocks.hpp"
#include "services/dds/sim_clock.hpp"
#include "simulationPubSubTypes.h"
#include "twin/geometry/product_loader.hpp"
#include "twin/model/source_ref.hpp"
#include "twin/orchestration/order_network.hpp"
#include "twin/orchestration/quote.hpp"
#include "twin/planning/build_orientation.hpp"
#include "twin/planning/sequence_planner.hpp"
#include "twin/planning/subassembly_planner.hpp"
#include "twin/report/gltf_animation.hpp"
#include "twin/report/html_report.hpp"
#include "twin/report/plan_json.hpp"
#include "twin/planning/work_memory.hpp"
#include "services/node/heartbeat.hpp"
#include "services/node/run.hpp"
#include "services/state/cell_store.hpp"

namespace {

// Why a plan is incomplete, in a line: its last finding but the orientations' summary.
std::string why_incomplete(const twin::Plan& plan) {
  for (auto f = plan.findings.rbegin(); f != plan.findings.rend(); ++f) {
    if (f->kind != "orientation") return f->message;
  }
  return "no complete plan";
}

const std::atomic<bool>& running = services::running_flag();

using dds::TopicKind;

cell::OrderState order_state(const std::string& s) {
  static const std::map<std::string, cell::OrderState> states = {
      {"SUBMITTED", cell::SUBMITTED}, {"PLANNING", cell::PLANNING}, {"VIRTUAL_ASSEMBLY", cell::VIRTUAL_ASSEMBLY},
      {"WAITING", cell::WAITING}, {"PHYSICAL_ASSEMBLY", cell::PHYSICAL_ASSEMBLY},
      {"DONE", cell::DONE}, {"FAILED", cell::FAILED}};
  return states.at(s);
}


struct Options {
  dds::ParticipantSettings dds;
  std::string order, product, out = ".", sequence = "search", path = "linear", state_dir;
  double wait_s = 30, lease_s = 5;
  fb::GripperGeometry gripper;
  bool fixtures = false;  // the cell holds what stands on nothing yet (PlannerOptions::fixtures)
  bool verbose = false;
  bool quiet = false;
  bool quote = false;
  twin::Rates rates;
};

class TwinProcess {
 public:
  // Joins the cell: nothing here depends on the order, which a standby twin learns later.
  explicit TwinProcess(const Options& o)
      : options_(o),
        participant_(dds::make_participant(o.order.empty() ? "twin-standby" : "twin-" + o.order, o.dds)),
        clock_(participant_) {
    dds::QosSettings qos;
    qos.liveliness_lease_s = o.lease_s;
    status_ = std::make_unique<dds::Writer<cell::OrderStatus, cell::OrderStatusPubSubType>>(
        participant_, "cell/orders/status", TopicKind::state, qos);
    result_ = std::make_unique<dds::Writer<cell::OrderResult, cell::OrderResultPubSubType>>(
        participant_, "cell/orders/result", TopicKind::state, qos);
  }

  void status(const std::string& state, const std::string& message, double progress) {
    cell::OrderStatus s;
    s.order_id(options_.order);
    s.state(order_state(state));
    s.message(message);
    s.progress(progress);
    s.sim_time(clock_.now());
    status_->write(s);
    if (store_ && state != stored_state_) {
      // The product is done: its parts on the station are counted as assembled from now on.
      if (state == "DONE") store_->assemble(options_.order);
      store_->set_order(options_.order, state, state == "FAILED" ? message : "", -1,
                        {"twin-" + options_.order, state, message});
      stored_state_ = state;
    }
    if (!options_.quiet) std::cout << "[" << options_.order << "] " << state << ": " << message << std::endl;
  }

  void result(bool complete, const std::string& plan_file, const std::string& animation, const std::string& error) {
    cell::OrderResult r;
    r.order_id(options_.order);
    r.complete(complete);
    r.plan_file(plan_file);
    r.animation_file(animation);
    r.error(error);
    result_->write(r);
  }

  // Plans `order`, then orchestrates it; returns the exit code.
  int run(const Options& order) {
    options_ = order;
    if (!options_.state_dir.empty()) store_ = std::make_unique<state::CellStore>(options_.state_dir);
    status("SUBMITTED", options_.product, 0);
    if (store_ && !take_up()) return end_with(1, "the work of its earlier twin did not end within 60 s");
    sim::MeshCache meshes;
    std::optional<twin::LoadedProduct> loaded;
    try {
      loaded.emplace(twin::load_product(options_.product, meshes));
      twin::require_geometry(*loaded);
    } catch (const twin::DescriptionError& e) {
      return end_with(2, std::string("bad product description: ") + e.what());
    }
    status("PLANNING", "planning " + std::to_string(loaded->product.parts().size()) + " parts", 0);
    auto path = twin::make_path_planner(options_.path);
    twin::PlannerOptions planning;
    planning.gripper = options_.gripper;
    planning.fixtures = options_.fixtures;
    planning.stop = [this] { return planning_stopped(); };
    twin::OrientedPlan oriented = plan_order(*loaded, *path, planning);
    if (!running) return end_with(1, "stopped while it was planned");
    if (!cancelled_by_.empty()) return end_with(1, "cancelled by " + cancelled_by_);
    const twin::LoadedProduct& product = oriented.product;  // as the cell builds it
    const twin::Plan& plan = oriented.plan;
    std::filesystem::create_directories(options_.out);
    const auto plan_file = std::filesystem::absolute(options_.out) / "plan.json";
    if (!plan.complete) {
      const std::string why = "planning found no complete assembly: " + why_incomplete(plan);
      if (options_.quote) return end_quote(product, twin::infeasible_quote(why, options_.rates), plan);
      write_plan(product, plan, plan_file);
      return end_with(1, why, plan_file.string());
    }
    return orchestrate(product, plan, plan_file);
  }

 private:
  // Asked between the planner's steps: the search runs on this thread for as long as it
  // needs, so the heartbeat beats here too.
  bool planning_stopped() {
    heartbeat_.beat();
    return !running || cancel_asked();
  }

  // Whether the operator asked to cancel the order (cellctl cancel, the dashboard): the cell's
  // state is read at most once a second, and a read the busy database refused is tried at the
  // next. Sets cancelled_by_.
  bool cancel_asked() {
    if (!cancelled_by_.empty()) return true;
    const auto now = std::chrono::steady_clock::now();
    if (!store_ || now - cancel_looked_at_ < std::chrono::seconds(1)) return false;
    cancel_looked_at_ = now;
    try {
      cancelled_by_ = store_->cancel_requested(options_.order);
    } catch (const state::StoreError& e) {
      std::cerr << "order " << options_.order << ": " << e.what() << '\n';
    }
    return !cancelled_by_.empty();
  }

  // A twin taking up an order whose physical assembly had begun follows the order its
  // predecessor stored (the parts in place were put in by it); where that no longer plans
  // (another cell-sim, another build), it plans anew and the journal says so.
  // Either may be in another orientation than the finished product's (build_orientation.hpp).
  twin::OrientedPlan plan_order(const twin::LoadedProduct& product, twin::PathPlanner& path,
                                const twin::PlannerOptions& options) {
    const auto stored = store_ ? store_->plan_of(options_.order) : std::vector<state::PlanStepRecord>{};
    if (!stored.empty()) {
      std::vector<std::string> ids;
      for (const auto& s : stored) ids.push_back(s.step);
      twin::GivenSequencePlanner given(ids);
      twin::OrientedPlan oriented = twin::plan_in_build_orientation(product, given, path, options);
      const twin::Plan& plan = oriented.plan;
      if (plan.complete) {
        store_->journal("twin-" + options_.order, "plan followed", options_.order,
                        "the stored order of " + std::to_string(stored.size()) + " steps");
        return oriented;
      }
      store_->journal("twin-" + options_.order, "plan not followed", options_.order,
                      "the stored order did not plan again: " + why_incomplete(plan));
    }
    const auto sequence = twin::make_sequence_planner(options_.sequence);
    return twin::plan_in_build_orientation(product, *sequence, path, options);
  }

  // The plan physical assembly follows, as virtual assembly validated it.
  void store_plan(const twin::LoadedProduct& product, const twin::Plan& plan) {
    std::vector<state::PlanStepRecord> steps;
    for (const auto& step : plan.steps) {
      const std::string& id = product.product.parts()[step.part].id;
      steps.push_back({step.carried.empty() ? id : twin::unit_id(id), step.trajectory.label});
    }
    try {
      store_->set_plan(options_.order, steps);
    } catch (const std::exception& e) {
      // The order goes on; a twin that takes it up would plan anew (and say so).
      std::cerr << "order " << options_.order << ": the plan was not stored: " << e.what() << '\n';
    }
  }

  // `reported`: the orchestrator has published FAILED already.
  int end_with(int code, const std::string& error, const std::string& plan_file = "", bool reported = false) {
    if (store_ && !running) {
      // The cell stops the twin (it goes down): the order is paused, not over. No final
      // status: the resources keep what it booked for the twin that takes it up.
      store_->set_order(options_.order, "INTERRUPTED", error, -1, {"twin-" + options_.order, "INTERRUPTED", error});
      std::cerr << "order " << options_.order << " paused: " << error << '\n';
      return code;
    }
    if (!reported) status("FAILED", error, 0);
    if (store_) store_->set_order(options_.order, "FAILED", error, code);
    result(false, plan_file, "", error);
    std::cerr << "error: order " << options_.order << ": " << error << '\n';
    linger();
    return code;
  }

  // A quote is the order's answer, feasible or not: quote.json beside plan.json and the
  // report (which says it at the top), and DONE.
  int end_quote(const twin::LoadedProduct& product, const twin::Quote& quote, const twin::Plan& plan) {
    const std::filesystem::path out(options_.out);
    std::ofstream(out / "quote.json") << twin::quote_json(options_.order, quote, plan.steps.size(), plan.findings).dump(2) << '\n';
    std::string summary = "quoted: not feasible: " + quote.reason;
    if (quote.feasible) {
      char text[200];
      std::snprintf(text, sizeof text, "quoted: done in %.0f s (%.0f s waiting for %s), %.2f %s", quote.makespan_s,
                    quote.wait_s, quote.station.c_str(), quote.total_cost, quote.currency.c_str());
      summary = text;
    }
    write_plan(product, plan, out / "plan.json", {}, summary);
    write_animation(product, plan);
    status("DONE", summary, 1);
    result(true, (out / "plan.json").string(), "", "");
    if (store_) store_->set_order(options_.order, "DONE", "", 0);
    linger();
    return 0;
  }

  // Where an earlier twin of the order left it (the cell's state): once the work it had
  // given the resources has ended (a robot carries on with its fetches), the parts in place
  // and at the dock are used as they are; one left in a gripper is set aside for inspection
  // and fetched anew. False when that work did not end in time.
  bool take_up() {
    for (const auto& o : store_->orders()) {
      if (o.order == options_.order) resume_.attempt = std::max(1, o.attempts);
    }
    // Even with no part handed out yet, a robot may still have the earlier twin's fetches.
    if (store_->parts(options_.order).empty() && store_->commands_of(options_.order).empty()) return true;
    status("SUBMITTED", "taking the order up where its earlier twin left it", 0);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    const auto in_transit = [&] {
      const auto parts = store_->parts(options_.order);
      return std::any_of(parts.begin(), parts.end(), [](const auto& p) { return p.place == state::Place::in_transit; });
    };
    while (!store_->commands_of(options_.order).empty() || in_transit()) {
      if (std::chrono::steady_clock::now() > deadline || !running) return false;
      heartbeat_.beat();
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    for (const auto& p : store_->parts(options_.order)) {
      resume_.used.insert(p.part);
      if (p.place == state::Place::in_gripper) {
        store_->set_aside(options_.order, p.part);
        store_->journal("twin-" + options_.order, "inspection", options_.order, p.part + " was in " + p.holder + "'s gripper");
      }
      if (p.place == state::Place::placed) (p.holder.empty() ? resume_.placed : resume_.aside).insert(p.part);
      if (p.place == state::Place::on_station) resume_.delivered.insert(p.part);
      if (p.place == state::Place::placed || p.place == state::Place::on_station || p.place == state::Place::in_gripper) {
        resume_.station = p.station;
      }
    }
    store_->journal("twin-" + options_.order, "taken up", options_.order,
                    std::to_string(resume_.placed.size()) + " parts in place, " + std::to_string(resume_.aside.size()) +
                        " built aside and " + std::to_string(resume_.delivered.size()) + " at the dock of " +
                        resume_.station);
    return true;
  }

  // Gives the last samples time to reach the readers before the participant goes.
  void linger() {
    status_->wait_for_readers(1, std::chrono::milliseconds(500));
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }

  // plan.json and, beside it, the designer's report.html (with the cell's run, once there is one).
  void write_plan(const twin::LoadedProduct& product, const twin::Plan& plan, const std::filesystem::path& file,
                  const twin::Timeline& timeline = {}, const std::string& answer = "") const {
    std::ofstream(file) << twin::plan_json(product.product, plan).dump(2) << '\n';
    twin::ReportOptions report;
    report.look.gripper = options_.gripper;
    report.title = options_.order;
    report.timeline = timeline;
    report.answer = answer;
    twin::write_html_report(product, plan, file.parent_path() / "report.html", report);
  }

  // animation.gltf in the order's folder; its path.
  std::filesystem::path write_animation(const twin::LoadedProduct& product, const twin::Plan& plan) const {
    const auto file = std::filesystem::absolute(options_.out) / "animation.gltf";
    twin::AnimationOptions look;
    look.gripper = options_.gripper;
    twin::write_gltf_animation(product, plan, file, look);
    return file;
  }

  using Inputs = std::vector<std::pair<const char*, const char*>>;  // (block, input)

  template <class T, class P>
  void subscribe(fb::Resource& r, const std::string& name, const std::string& topic, TopicKind kind,
                 std::function<fb::Data(const T&)> to_data, const Inputs& on_sample, const Inputs& on_gone = {}) {
    auto& block = r.add(std::make_unique<dds::SubscribeBlock<T, P>>(name, participant_, topic, kind, std::move(to_data)));
    for (const auto& [to, input] : on_sample) r.connect(name, "IND", to, input);
    for (const auto& [to, input] : on_gone) r.connect(name, "GONE", to, input);
    starters_.push_back([&block] { block.start(); });
  }
  template <class T, class P>
  dds::PublishBlock<T, P>& publish(fb::Resource& r, const std::string& name, const std::string& topic,
                                   const char* from, const char* output, std::function<T(const fb::Data&)> to_sample) {
    auto& block = r.add(std::make_unique<dds::PublishBlock<T, P>>(name, participant_, topic, TopicKind::events,
                                                                  std::move(to_sample)));
    r.connect(from, output, name, "REQ");
    return block;
  }

  int orchestrate(const twin::LoadedProduct& product, const twin::Plan& plan, const std::filesystem::path& plan_file) {
    fb::Resource r("twin-" + options_.order, 4096);
    twin::OrderSettings settings;
    settings.order_id = options_.order;
    settings.resume = resume_;
    settings.take_up_after_restart = store_ && store_->awaits_twin(options_.order);
    settings.wait_timeout = std::chrono::milliseconds(static_cast<long>(options_.wait_s * 1000));
    settings.gripper = options_.gripper;
    settings.quote_only = options_.quote;
    settings.replanning.fixtures = options_.fixtures;
    settings.replanning.stop = [this] { return planning_stopped(); };
    settings.real_time_factor = [this] { return clock_.real_time_factor(); };
    fb::NegotiationSettings negotiation;
    negotiation.wait = settings.wait_timeout;
    auto& orchestrator = twin::add_order_network(r, product, plan, settings, negotiation);

    subscribe<cell::Capability, cell::CapabilityPubSubType>(
        r, "capabilities", "cell/capabilities", TopicKind::state,
        [](const cell::Capability& c) { return dds::to_data(c); },
        {{"orchestrator", "CAPABILITY"}, {"negotiator", "CAPABILITY"}},
        {{"orchestrator", "RESOURCE_GONE"}, {"negotiator", "RESOURCE_GONE"}});
    subscribe<cell::CellRoster, cell::CellRosterPubSubType>(
        r, "roster", "cell/roster", TopicKind::state,
        [](const cell::CellRoster& roster) {
          std::string lines;
          for (const auto& e : roster.resources()) lines += e.resource_id().to_string() + "\t" + e.kind().to_string() + "\n";
          return fb::Data{{"resources", lines}};
        },
        {{"negotiator", "ROSTER"}});
    subscribe<cell::Proposal, cell::ProposalPubSubType>(
        r, "proposals", "cell/negotiation/proposals", TopicKind::events,
        [](const cell::Proposal& p) { return dds::to_data(p); }, {{"negotiator", "PROPOSAL"}});
    subscribe<cell::AwardReply, cell::AwardReplyPubSubType>(
        r, "award_replies", "cell/negotiation/replies", TopicKind::events,
        [](const cell::AwardReply& a) { return dds::to_data(a); }, {{"negotiator", "AWARD_REPLY"}});
    subscribe<cell::CommandEvent, cell::CommandEventPubSubType>(
        r, "command_events", "cell/command_events", TopicKind::events, [this](const cell::CommandEvent& e) {
          clock_.observe(e.sim_time());
          if (e.order_id().to_string() != options_.order) return fb::Data{};  // another order's
          if (options_.verbose) std::cout << "  event " << e.command_id() << " " << dds::state_name(e.state()) << " " << e.reason() << std::endl;
          return fb::Data{{"command_id", e.command_id().to_string()}, {"order_id", e.order_id().to_string()},
                          {"resource_id", e.resource_id().to_string()},
                          {"state", std::string(dds::state_name(e.state()))}, {"reason", e.reason().to_string()},
                          {"sim_time", e.sim_time()}};
        }, {{"orchestrator", "COMMAND_EVENT"}});
    subscribe<cell::SimReply, cell::SimReplyPubSubType>(
        r, "sim_replies", "cell/sim/replies", TopicKind::events, [this](const cell::SimReply& s) {
          if (s.requester().to_string() != options_.order) return fb::Data{};  // another requester's
          clock_.observe(s.end_time());
          if (options_.verbose) std::cout << "  sim reply " << s.request_id() << " " << s.ok() << " " << s.error() << std::endl;
          return dds::to_data(s);
        }, {{"orchestrator", "SIM_REPLY"}});

    publish<cell::CallForProposals, cell::CallForProposalsPubSubType>(
        r, "calls", "cell/negotiation/calls", "negotiator", "CFP", [](const fb::Data& d) { return dds::to_call(d); });
    publish<cell::Award, cell::AwardPubSubType>(r, "awards", "cell/negotiation/awards", "negotiator", "AWARD",
                                                [](const fb::Data& d) { return dds::to_award(d); });
    publish<cell::Release, cell::ReleasePubSubType>(r, "releases", "cell/negotiation/releases", "orchestrator",
                                                    "RELEASE", [](const fb::Data& d) { return dds::to_release(d); });
    r.add(std::make_unique<dds::RoutedPublishBlock<cell::Command, cell::CommandPubSubType>>(
        "commands", participant_,
        [](const fb::Data& d) { return dds::command_topic(fb::get<std::string>(d, "resource_id")); },
        [this](const fb::Data& d) {
          cell::Command c = dds::to_command(d);
          c.sim_time(clock_.now());
          if (options_.verbose) std::cout << "  command " << c.command_id() << " to " << c.resource_id() << std::endl;
          return c;
        },
        dds::command_qos()));
    r.connect("orchestrator", "COMMAND", "commands", "REQ");
    r.connect("orchestrator", "PREPARE", "commands", "PREPARE");
    publish<cell::CancelRequest, cell::CancelRequestPubSubType>(r, "cancels", "cell/cancel_requests", "orchestrator",
                                                                "CANCEL", [this](const fb::Data& d) {
                                                                  cell::CancelRequest c;
                                                                  c.command_id(fb::get<std::string>(d, "command_id"));
                                                                  c.order_id(options_.order);
                                                                  return c;
                                                                });
    auto& sim = publish<cell::SimRequest, cell::SimRequestPubSubType>(
        r, "sim_requests", "cell/sim/requests", "orchestrator", "SIM", [this](const fb::Data& d) {
          if (options_.verbose) std::cout << "  sim " << fb::get<std::string>(d, "request_id") << " "
                                          << fb::get<std::string>(d, "kind") << " " << fb::get<std::string>(d, "body_id") << std::endl;
          return dds::to_sim_request(d);
        });
    r.add(std::make_unique<fb::ActionBlock>("status", [this, &product, &orchestrator](const fb::Data& d) {
      const std::string& state = fb::get<std::string>(d, "state");
      if (store_ && state == "PHYSICAL_ASSEMBLY" && stored_state_ != state) store_plan(product, orchestrator.plan());
      status(state, fb::get<std::string>(d, "message"), fb::get<double>(d, "progress"));
    }));
    r.connect("orchestrator", "STATUS", "status", "REQ");
    std::vector<twin::Finding> findings;
    r.add(std::make_unique<fb::ActionBlock>("findings", [&findings](const fb::Data& d) {
      findings.push_back({fb::get<std::string>(d, "kind"), fb::get<std::string>(d, "message"),
                          {fb::get<std::string>(d, "part")}});
      std::cout << "finding: " << fb::get<std::string>(d, "message") << std::endl;  // also when quiet
    }));
    r.connect("orchestrator", "FINDING", "findings", "REQ");
    std::optional<twin::Quote> quote;
    r.add(std::make_unique<fb::ActionBlock>("quote", [this, &quote](const fb::Data& d) {
      quote = twin::price_quote({fb::get<std::string>(d, "station"), fb::get<std::string>(d, "robot"),
                                 fb::get<double>(d, "wait"), fb::get<double>(d, "makespan"), fb::get<double>(d, "robot_s")},
                                options_.rates);
    }));
    r.connect("orchestrator", "QUOTE", "quote", "REQ");
    bool finished = false;
    r.add(std::make_unique<fb::ActionBlock>("finished", [&finished](const fb::Data&) { finished = true; }));
    r.connect("orchestrator", "FINISHED", "finished", "REQ");

    for (auto& start : starters_) start();
    const auto wait = std::chrono::milliseconds(static_cast<long>(options_.wait_s * 1000));
    bool sim_found = false;  // asked a second at a time, beating: the desk's watchdog may be shorter than the wait
    for (std::chrono::milliseconds waited{0}; !sim_found && waited < wait && running; waited += std::chrono::seconds(1)) {
      heartbeat_.beat();
      sim_found = sim.writer().wait_for_readers(1, std::chrono::seconds(1));
    }
    if (!running) return end_with(1, "stopped while it waited for the cell");
    if (!sim_found) {
      return end_with(1, "cell-sim did not appear within " + std::to_string(static_cast<int>(options_.wait_s)) +
                             " s: is the cell up on domain " + std::to_string(options_.dds.domain_id) + "?");
    }
    r.post("orchestrator", "START");
    auto last_tick = std::chrono::steady_clock::now();
    bool cancelled = false;
    while (!finished && running) {
      heartbeat_.beat();
      r.wait_and_run_one(std::chrono::milliseconds(50));
      const auto now = std::chrono::steady_clock::now();
      if (now - last_tick > std::chrono::milliseconds(100)) {
        last_tick = now;
        r.post("orchestrator", "TICK");
        r.post("negotiator", "TICK");
      }
      if (!cancelled && cancel_asked()) {
        cancelled = true;
        r.post("orchestrator", "STOP", {{"reason", "cancelled by " + cancelled_by_}});
      }
    }
    // Ends us if the DDS entities' teardown hangs (it does, now and then, in Fast DDS 2.9.1's
    // deadlock of a writer's reader removal against its flow controller: heartbeat.hpp). The
    // order's results are written before it; 15 s (was 30) is what a hang costs the order's
    // next twin, and a test that waits for the twin's end (one waited 30 s under TSan).
    services::ExitWatchdog watchdog(std::chrono::seconds(15));
    if (!finished) return watchdog.exit(end_with(1, "stopped before the order ended"));
    if (orchestrator.take_up()) {
      // Nothing released, no final status: the cell's next twin takes the order up.
      store_->set_order(options_.order, "INTERRUPTED", orchestrator.error(), -1,
                        {"twin-" + options_.order, "to be taken up", orchestrator.error()});
      std::cerr << "order " << options_.order << ": " << orchestrator.error() << "; the next twin takes it up\n";
      return watchdog.exit(3);
    }

    // What the designer gets: the plan as virtual assembly validated it (replanned if cell-sim
    // made it go back), planning's and virtual assembly's findings, and the animation.
    twin::Plan validated = orchestrator.plan();
    validated.findings.insert(validated.findings.end(), findings.begin(), findings.end());
    if (options_.quote) {
      const auto why = twin::infeasible_quote(orchestrator.error(), options_.rates);
      return watchdog.exit(end_quote(product, quote ? *quote : why, validated));
    }
    write_plan(product, validated, plan_file, orchestrator.timeline());
    const auto animation = write_animation(product, validated);
    if (!orchestrator.error().empty()) return watchdog.exit(end_with(1, orchestrator.error(), plan_file.string(), true));
    result(true, plan_file.string(), animation.string(), "");
    if (store_) store_->set_order(options_.order, "DONE", "", 0);
    linger();
    return watchdog.exit(0);
  }

  Options options_;
  dds::ParticipantPtr participant_;
  dds::SimClock clock_;
  std::unique_ptr<dds::Writer<cell::OrderStatus, cell::OrderStatusPubSubType>> status_;
  std::unique_ptr<dds::Writer<cell::OrderResult, cell::OrderResultPubSubType>> result_;
  std::vector<std::function<void()>> starters_;
  std::unique_ptr<state::CellStore> store_;  // the cell's durable state, if it keeps one
  std::string cancelled_by_;                  // who asked to cancel the order, once read (cancel_asked)
  std::chrono::steady_clock::time_point cancel_looked_at_{};
  twin::Resume resume_;
  std::string stored_state_;
  // To cellctl up's desk, which ends a twin that falls silent (cell_config.hpp, twin_watchdog).
  services::Heartbeat heartbeat_;
};

}  // namespace

namespace {

// What one order is: on the command line, or for a standby twin on its standard input.
void add_order_options(CLI::App& app, Options& o, std::vector<std::string>& rates) {
  app.add_option("--order", o.order, "Order id");
  app.add_option("--product", o.product, "The product's AutomationML file");
  app.add_option("--out", o.out, "Folder for report.html, plan.json and animation.gltf");
  app.add_option("--sequence", o.sequence, "Sequence planner")->check(CLI::IsMember({"paper", "search"}));
  app.add_option("--path", o.path, "Path planner")->check(CLI::IsMember({"linear", "ompl"}));
  app.add_option("--wait", o.wait_s, "How long to wait for the cell's resources, s")->check(CLI::PositiveNumber);
  dds::add_state_option(app, o.state_dir);
  dds::add_gripper_options(app, o.gripper);
  app.add_flag("--fixtures", o.fixtures,
               "The cell has fixtures: a plan that needs one to hold a part that stands on nothing yet is complete");
  app.add_flag("--quote", o.quote, "Assemble virtually only and answer with quote.json: time and cost here, findings");
  app.add_option("--setup-cost", o.rates.setup_cost, "Quote: the fixed cost of an order")->check(CLI::NonNegativeNumber);
  app.add_option("--cost-per-hour", rates, "Quote: RESOURCE=COST, for each hour the order uses the resource");
  app.add_option("--currency", o.rates.currency, "Quote: the currency of the costs");
}

// After parsing: the rates (CLI11 takes a map option only as two words per entry) and the
// options an order cannot go without. An error's text, or empty.
std::string finish_order_options(const std::vector<std::string>& rates, Options& o) {
  for (const auto& r : rates) {
    const auto eq = r.find('=');
    double cost = -1;
    try {
      std::size_t used = 0;
      if (eq != std::string::npos && eq > 0) cost = std::stod(r.substr(eq + 1), &used);
      if (used != r.size() - eq - 1) cost = -1;
    } catch (const std::exception&) {
    }
    if (!(cost >= 0 && std::isfinite(cost))) return "--cost-per-hour " + r + ": give RESOURCE=COST, a number >= 0";
    o.rates.per_hour[r.substr(0, eq)] = cost;
  }
  if (o.order.empty() || o.product.empty()) return "an order needs --order and --product";
  return "";
}

// A standby twin's order: its options from standard input, one per line, up to an empty line.
// False when the input ends first or the twin is stopped (no order came: nothing to do).
bool read_standby_order(std::vector<std::string>& args) {
  std::string line;
  while (running) {
    pollfd in{STDIN_FILENO, POLLIN, 0};
    if (::poll(&in, 1, 100) <= 0) continue;  // a time-out, or a signal: look at `running`
    char c = 0;
    if (::read(STDIN_FILENO, &c, 1) != 1) return false;
    if (c != '\n') {
      line += c;
    } else if (line.empty()) {
      return true;
    } else {
      args.push_back(std::move(line));
      line.clear();
    }
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  twin::keep_work_memory();
  CLI::App app{"twin: the digital twin of one order"};
  Options o;
  bool all_interfaces = false, standby = false;
  std::vector<std::string> rates;
  dds::add_dds_options(app, o.dds, all_interfaces);
  app.add_option("--lease", o.lease_s, "Liveliness lease of the order's status, s")->check(CLI::PositiveNumber);
  app.add_flag("--verbose", o.verbose, "Print every command, cell-sim request and answer");
  app.add_flag("--quiet", o.quiet, "Do not print the order's status (whoever started the twin shows it)");
  app.add_flag("--standby", standby,
               "Join the cell now, then read the order's options (--order, --product, ...) from standard input, "
               "one per line, ended by an empty line");
  add_order_options(app, o, rates);
  CLI11_PARSE(app, argc, argv);
  dds::apply_interfaces(o.dds, all_interfaces);
  if (!o.dds.security.dir.empty() && o.dds.security.identity.empty()) {
    // Whoever starts a twin gives it an identity and binds its order to it (docs/security.md).
    std::cerr << "error: a twin with --security needs --identity (twin-1 .. twin-N: cellctl starts twins so)\n";
    return 2;
  }
  services::run_until_signalled();
  if (standby && !o.order.empty()) {
    std::cerr << "error: a standby twin reads its order from standard input, not --order\n";
    return 2;
  }
  const std::string bad = standby ? "" : finish_order_options(rates, o);
  if (!bad.empty()) {
    std::cerr << "error: " << bad << '\n';
    return 2;
  }
  try {
    TwinProcess twin(o);
    if (standby) {
      std::vector<std::string> args;
      if (!read_standby_order(args)) return 0;
      CLI::App order_app{"the standby twin's order"};
      add_order_options(order_app, o, rates);
      std::reverse(args.begin(), args.end());  // CLI11 takes a vector last argument first
      try {
        order_app.parse(args);
      } catch (const CLI::ParseError& e) {
        return order_app.exit(e);
      }
      if (const std::string why = finish_order_options(rates, o); !why.empty()) {
        std::cerr << "error: " << why << '\n';
        return 2;
      }
    }
    return twin.run(o);
  } catch (const std::exception& e) {
    std::cerr << "error: twin " << o.order << ": " << e.what() << '\n';
    return 1;
  }
}
