#include "twin/orchestration/order_orchestrator.hpp"

#include <algorithm>
#include <limits>

#include "services/blocks/sample_checks.hpp"
#include "services/node/restart_reason.hpp"
#include "twin/planning/subassembly_planner.hpp"

namespace twin {
namespace {

using fb::Data;
using fb::get;
using fb::Numbers;

}  // namespace

OrderOrchestrator::OrderOrchestrator(std::string name, const LoadedProduct& product, const Plan& plan,
                                     OrderSettings settings)
    : BasicChart(std::move(name), Phase::idle), product_(product), plan_(plan),
      settings_(std::move(settings)), sim_(settings_.order_id), booking_(settings_.order_id) {
  declare_input("START");
  declare_input("TICK");
  declare_input("STOP", {"reason"});
  declare_input("CAPABILITY", {"resource_id", "kind", "position", "dock", "speed", "angular_speed", "reserved_by",
                               "waiting"});
  declare_input("RESOURCE_GONE", {"resource_id"});
  declare_input("AWARDED", {"call_id", "resource_id", "ahead"});
  declare_input("QUOTED", {"call_id", "resource_id", "earliest_start", "duration", "bid_time"});
  declare_input("UNAVAILABLE", {"call_id", "reason"});
  declare_input("COMMAND_EVENT", {"command_id", "order_id", "state", "reason", "sim_time"});
  declare_input("SIM_REPLY", {"request_id", "ok", "error", "collided"});
  declare_output("CALL", {"call_id", "operation", "part_type", "station", "sources", "count", "duration"});
  declare_output("ASK", {"call_id", "operation", "part_type", "station", "sources", "count", "duration"});
  declare_output("QUOTE", {"station", "robot", "wait", "makespan", "robot_s"});
  for (const char* out : {"RELEASE", "COMMAND", "CANCEL", "SIM"}) declare_output(out);
  declare_output("PREPARE", {"resource_id"});
  declare_output("STATUS", {"state", "message", "progress"});
  declare_output("FINDING", {"kind", "message", "part"});
  declare_output("PLACED", {"part", "aside"});
  declare_output("FINISHED", {"complete", "error", "take_up"});

  const Phase all_states[] = {Phase::idle,   Phase::waiting_cell, Phase::virtual_assembly, Phase::booking,
                              Phase::queued, Phase::hiring,       Phase::physical,         Phase::quoting,
                              Phase::cleanup, Phase::ended};
  // What the cell's resources say of themselves, in every state; a place that is no place
  // (a position that is not finite) is not taken.
  const auto is_place = [](const Data& d) {
    fb::SampleCheck check(d);
    check.vector("position").vector("dock").at_least("speed", 0).at_least("angular_speed", 0);
    return check.ok();
  };
  for (const Phase in : all_states) {
    transition(in, "CAPABILITY", in, [this, is_place](const Data& d) {
      if (!is_place(d)) return;
      Place& p = places_[get<std::string>(d, "resource_id")];
      p = {get<std::string>(d, "kind"), get<Numbers>(d, "position"), get<Numbers>(d, "dock"), get<double>(d, "speed"),
           get<double>(d, "angular_speed"), get<std::string>(d, "reserved_by"),
           fb::split_names(get<std::string>(d, "waiting"))};
      const std::string& id = get<std::string>(d, "resource_id");
      if (state() == Phase::waiting_cell) try_begin_virtual();
      if (state() == Phase::queued && id == booking_.station()) on_queue_news(p);
      if (state() == Phase::queued && p.kind == "station" && id != booking_.station()) consider_moving_to(id);
      if (state() == Phase::hiring && id == booking_.arm_resource() && p.reserved_by == settings_.order_id) arm_held_ = true;
      if (state() == Phase::hiring) start_physical_when_hired();
      if (state() == Phase::quoting) quote_when_arm_known();
    });
  }

  // cell-sim is pinged until it answers: then requests and replies both get through. Once a
  // second: sixty twins pinging at every tick were 600 requests a second for a cell-sim that
  // had their virtual assemblies to do, and its answers came later still.
  transition(Phase::idle, "START", Phase::waiting_cell, [this](const Data&) {
    waiting_since_ = std::chrono::steady_clock::now();
    status("PLANNING", "planned " + std::to_string(plan_.steps.size()) + " steps; waiting for a station of the cell", 0);
    ask_sim(sim_.ping());
  });
  transition(Phase::waiting_cell, "SIM_REPLY", Phase::waiting_cell, [this](const Data&) {
    sim_answers_ = true;
    try_begin_virtual();
  });
  transition(Phase::waiting_cell, "TICK", Phase::waiting_cell, [this](const Data&) {
    if (waited_too_long()) {
      return fail(std::string(sim_answers_ ? "no station of the cell appeared" : "cell-sim did not answer") +
                  " within " + std::to_string(settings_.wait_timeout.count() / 1000) + " s: is the cell up?");
    }
    if (!sim_answers_ && std::chrono::steady_clock::now() - asked_sim_at_ >= std::chrono::seconds(1)) ask_sim(sim_.ping());
  });
  transition(Phase::waiting_cell, "CELL_READY", Phase::virtual_assembly, [this](const Data&) { begin_virtual(); });

  // Cell-sim's answers, in the states that send it requests.
  for (const Phase in : {Phase::virtual_assembly, Phase::physical, Phase::cleanup}) {
    transition(in, "SIM_REPLY", in, [this](const Data& d) {
      if (!action_running_ || get<std::string>(d, "request_id") != awaited_id_) return;
      if (state() == Phase::cleanup) return action_done();
      if (!get<bool>(d, "ok") && get<std::string>(d, "error").rfind("busy:", 0) == 0) {
        // Asked again at the next tick, but not for ever: a cell-sim busy this long (or a
        // sender that only answers so) fails the order with the reason.
        if (++busy_answers_ > kMaxBusyAnswers) return fail("cell-sim refused: " + get<std::string>(d, "error"));
        sim_busy_ = true;
        return;
      }
      busy_answers_ = 0;
      if (!get<bool>(d, "ok") && actions_.front().may_fail) return action_done();
      if (!get<bool>(d, "ok")) return fail("cell-sim refused: " + get<std::string>(d, "error"));
      if (fb::get_or<bool>(d, "collided", false) && actions_.front().retry_on_collision) {
        std::string reason;
        fb::move_outcome(d, reason);
        return on_collision(reason);
      }
      action_done();
    });
  }

  // Booking a station, then hiring what physical assembly needs there.
  transition(Phase::virtual_assembly, "VIRTUAL_DONE", Phase::quoting, [this](const Data&) { ask_for_quotes(); },
             [this](const Data&) { return settings_.quote_only; });
  transition(Phase::virtual_assembly, "VIRTUAL_DONE", Phase::booking, [this](const Data&) { book(); });
  for (const Phase in : {Phase::booking, Phase::queued, Phase::hiring, Phase::quoting}) {
    transition(in, "UNAVAILABLE", in, [this](const Data& d) { fail(get<std::string>(d, "reason")); });
  }
  for (const Phase in : {Phase::booking, Phase::queued, Phase::hiring}) {
    transition(in, "AWARDED", in, [this](const Data& d) { on_awarded(d); });
  }
  for (const Phase in : {Phase::booking, Phase::queued}) {
    transition(in, "WAITS", Phase::queued, [this](const Data& d) {
      if (const auto p = places_.find(booking_.station()); p != places_.end()) on_queue_news(p->second);
      if (ahead_ < 0) report_place(get<std::int64_t>(d, "ahead"));
    });
    transition(in, "STATION_OURS", Phase::hiring, [this](const Data&) { hire(); });
  }
  transition(Phase::queued, "REBOOK", Phase::booking, [this](const Data& d) { book(get<std::string>(d, "only")); });
  transition(Phase::hiring, "HIRED", Phase::physical, [this](const Data&) { plan_physical(); });
  transition(Phase::quoting, "QUOTED", Phase::quoting, [this](const Data& d) { on_quoted(d); });
  transition(Phase::quoting, "TICK", Phase::quoting, [this](const Data&) {
    if (!booking_.robot().empty() && waited_too_long()) {
      fail("the arm of " + booking_.station() + " did not say its speed (no capability heard)");
    }
  });
  transition(Phase::quoting, "PRICED", Phase::ended, [this](const Data& quote) {
    emit("QUOTE", quote);
    emit("FINISHED", {{"complete", true}, {"error", std::string()}, {"take_up", false}});
  });
  for (const Phase in : all_states) {
    transition(in, "RESOURCE_GONE", in, [this](const Data& d) { on_resource_gone(get<std::string>(d, "resource_id")); });
  }

  transition(Phase::physical, "COMMAND_EVENT", Phase::physical, [this](const Data& d) {
    if (get<std::string>(d, "order_id") != settings_.order_id) return;
    const std::string& id = get<std::string>(d, "command_id");
    unheard_.erase(id);
    record(d);
    const std::string& state = get<std::string>(d, "state");
    if (const auto fetch = fetch_of_.find(id); fetch != fetch_of_.end()) {
      if (state == "aborted" || state == "rejected") {
        return fail("fetching " + product_.product.parts()[fetch->second].name + " failed: " + get<std::string>(d, "reason"));
      }
      if (state == "succeeded") delivered_.insert(id);
      if (!action_running_ || awaited_id_ != id) return;
      const Action::Kind awaiting = actions_.front().kind;
      if (awaiting == Action::send_heard || (awaiting == Action::await_delivery && state == "succeeded")) action_done();
      return;
    }
    if (!action_running_ || id != awaited_id_) return;
    if (state == "succeeded") return action_done();
    if (state != "aborted" && state != "rejected") return;
    fail(fb::get_or<std::string>(d, "resource_id", "") + " " + get<std::string>(actions_.front().data, "operation") +
         " failed: " + get<std::string>(d, "reason"));
  });
  transition(Phase::cleanup, "COMMAND_EVENT", Phase::cleanup, [this](const Data& d) {
    unheard_.erase(get<std::string>(d, "command_id"));
    record(d);
    if (action_running_ && get<std::string>(d, "command_id") == awaited_id_ &&
        get<std::string>(d, "state") != "accepted" && get<std::string>(d, "state") != "executing") {
      action_done();
    }
  });
  transition(Phase::physical, "TICK", Phase::physical, [this](const Data&) {
    resend_unheard();
    ask_sim_again();
  });
  transition(Phase::virtual_assembly, "TICK", Phase::virtual_assembly, [this](const Data&) {
    // Answered at once by a cell-sim that works (a virtual move takes no sim time): one that
    // stays silent is hung or gone, and the order fails saying so instead of waiting for ever.
    if (sim_silent()) {
      return fail("cell-sim did not answer request " + awaited_id_ + " (" + get<std::string>(actions_.front().data, "kind") +
                  " in virtual assembly) within " + std::to_string(settings_.wait_timeout.count() / 1000) + " s");
    }
    ask_sim_again();
  });
  transition(Phase::physical, "PHYSICAL_DONE", Phase::cleanup, [this](const Data&) { plan_cleanup(); });

  // A failure anywhere cancels undelivered fetches (fail) and cleans up; the order's twin
  // ends at once to be taken up again (take_up_after_restart).
  for (const Phase in : {Phase::waiting_cell, Phase::virtual_assembly, Phase::booking, Phase::queued, Phase::hiring,
                         Phase::physical, Phase::quoting}) {
    transition(in, "FAILED", Phase::cleanup, [this](const Data&) { plan_cleanup(); });
    // The operator cancelled the order: a failure like any other, with that reason.
    transition(in, "STOP", in, [this](const Data& d) { fail(get<std::string>(d, "reason")); });
  }
  transition(Phase::physical, "TAKE_UP", Phase::ended, [this](const Data&) {
    emit("FINISHED", {{"complete", false}, {"error", error_}, {"take_up", true}});
  });
  transition(Phase::cleanup, "TICK", Phase::cleanup, [this](const Data&) {
    if (std::chrono::steady_clock::now() - waiting_since_ > settings_.cleanup_timeout) raise("CLEANED");
  });
  transition(Phase::cleanup, "CLEANED", Phase::ended, [this](const Data&) { finish(); });
}

// --- booking and hiring --------------------------------------------------------------------

bool OrderOrchestrator::waited_too_long() const {
  return std::chrono::steady_clock::now() - waiting_since_ > settings_.wait_timeout;
}

// Virtual assembly happens at a station's place (any: it sees the fixtures, not the station's
// work), in the order's own scene.
void OrderOrchestrator::try_begin_virtual() {
  for (const auto& [id, p] : places_) {
    if (p.kind == "arm" && p.speed > 0) {
      settings_.arm_speed = p.speed;
      settings_.arm_angular_speed = p.angular_speed;
    }
    if (p.kind == "station" && virtual_station_.empty()) {
      virtual_station_ = id;
      virtual_place_ = location(id);  // kept: that station may leave while the order assembles virtually
    }
  }
  if (!virtual_station_.empty() && sim_answers_) raise("CELL_READY");
}

void OrderOrchestrator::begin_virtual() {
  status("VIRTUAL_ASSEMBLY", "virtual assembly in cell-sim", 0);
  step_ = candidate_ = 0;
  if (plan_.steps.empty()) return raise("VIRTUAL_DONE");
  if (settings_.resume.attempt > 1) {
    // An earlier twin of the order may have died in the middle of it: its virtual bodies
    // are still in the order's scene (cell-sim keeps them for the order), in the way.
    std::vector<std::string> left = virtual_gripper();
    for (PartIndex p = 0; p < product_.product.parts().size(); ++p) left.push_back(virtual_body(p));
    for (const auto& body : left) actions_.push_back({Action::sim, sim_.remove(body), false, true});
  }
  add_candidate(0, 0);
  next_action();
}

// A station's arm stands at the station's place.
const OrderOrchestrator::Place* OrderOrchestrator::arm_at(const std::string& station) const {
  const auto s = places_.find(station);
  if (s == places_.end()) return nullptr;
  for (const auto& [id, p] : places_) {
    if (p.kind == "arm" && p.speed > 0 && p.position == s->second.position) return &p;
  }
  return nullptr;
}

// The station's arm once its capability is heard; until then, at the speed virtual assembly
// used. A robot not known drives in no time; a place not known is the station's.
ModelledRun OrderOrchestrator::modelled(const Hired& h, double station_free, double robot_free) const {
  PhysicalScript script;
  {
    fb::SimRequests sim("model");
    std::size_t count = 0;
    script = physical_script(product_, plan_, geometry_, h, settings_.resume, sim,
                             [&count](const std::string& resource, const std::string& operation, const std::string& part) {
                               return Data{{"command_id", "model/" + std::to_string(++count)}, {"resource_id", resource},
                                           {"operation", operation}, {"part", part}};
                             });
  }
  ResourceModels models;
  for (const auto& [id, place] : h.places) models.docks[id] = place.dock;
  const Numbers& station_dock = h.places.at(h.station).dock;
  const auto robot = places_.find(h.robot);
  const bool robot_known = robot != places_.end() && robot->second.speed > 0 && robot->second.position.size() >= 3;
  models.robot_at = robot_known ? robot->second.position : station_dock;
  models.robot_speed = robot_known ? robot->second.speed : std::numeric_limits<double>::infinity();
  const Place* arm = arm_at(h.station);
  models.arm_speed = arm ? arm->speed : settings_.arm_speed;
  models.arm_angular_speed = arm ? arm->angular_speed : settings_.arm_angular_speed;
  models.real_time_factor = settings_.real_time_factor ? settings_.real_time_factor() : 0;
  return run_script(script.actions, models, station_free, robot_free);
}

// The script is built and run again only when what it depends on changed: the bidding asks
// for every station's hold at each decision.
double OrderOrchestrator::hold_at(const std::string& station) const {
  const auto place = places_.find(station);
  if (place == places_.end()) {
    // Its capability lapsed a moment (a starved station): its hold as it was last known.
    const auto known = holds_.find(station);
    return known == holds_.end() ? -1 : known->second.second;
  }
  const Place* arm = arm_at(station);
  std::vector<double> depends_on = place->second.position;
  depends_on.insert(depends_on.end(), place->second.dock.begin(), place->second.dock.end());
  depends_on.push_back(arm ? arm->speed : settings_.arm_speed);
  depends_on.push_back(arm ? arm->angular_speed : settings_.arm_angular_speed);
  depends_on.push_back(settings_.real_time_factor ? settings_.real_time_factor() : 0);
  auto& known = holds_[station];
  if (known.first == depends_on) return known.second;
  // Every part at the dock already: what the arm does there.
  Hired h{settings_.order_id, station, "arm", "", {}, {}};
  h.places[station] = location(station);
  for (const auto& type : fetched_types()) h.buffer_of[type] = station;
  const ModelledRun run = modelled(h, 0, 0);
  known = {depends_on, run.end - run.start};
  return known.second;
}

void OrderOrchestrator::book(std::string only) {
  if (only.empty()) only = settings_.resume.station;  // its parts stand there
  ahead_ = -1;
  waiting_since_ = std::chrono::steady_clock::now();
  const std::string why = only == settings_.resume.station ? ", where its parts stand" : ", whose queue is shorter";
  status("WAITING", only.empty() ? "virtual assembly done; booking a station" : "booking " + only + why, 0);
  emit("CALL", booking_.host(only, std::max(0.0, hold_at(only.empty() ? virtual_station_ : only))));
}

// Orders booked at the same moment see the same bids and may crowd one station: an order
// that waits moves to another station whose queue is shorter by two or more, or that is free.
// A station reserved for this order already is free for it: an earlier twin of the order
// queued there, and the station kept the booking through the restart.
void OrderOrchestrator::consider_moving_to(const std::string& station) {
  if (!settings_.resume.station.empty()) return;
  const Place& p = places_.at(station);
  const long load = p.reserved_by == settings_.order_id
                        ? 0
                        : (p.reserved_by.empty() ? 0 : 1) + static_cast<long>(p.waiting.size());
  if (ahead_ < 1 || !(load == 0 || load + 1 < ahead_)) return;
  emit("RELEASE", {{"order_id", settings_.order_id}, {"resource_id", booking_.station()}});
  booking_.leave_station();
  raise("REBOOK", {{"only", station}});
}

void OrderOrchestrator::on_resource_gone(const std::string& id) {
  places_.erase(id);
  const auto& buffers = booking_.buffer_of();
  if (state() == Phase::quoting && (id == booking_.station() || id == booking_.robot() ||
                                    std::any_of(buffers.begin(), buffers.end(), [&id](const auto& b) { return b.second == id; }))) {
    return fail(id + " disappeared while the order asked for quotes");
  }
  if (state() == Phase::queued && id == booking_.station()) {
    booking_.leave_station();
    emit("FINDING", {{"kind", std::string("rebooked")},
                     {"message", id + " disappeared while the order waited for it; booking another station"},
                     {"part", std::string()}});
    return raise("REBOOK", {{"only", std::string()}});
  }
  if ((state() == Phase::hiring || state() == Phase::physical) && booking_.holds(id)) {
    fail(id + " disappeared (its liveliness lease ran out)");
  }
}

void OrderOrchestrator::on_queue_news(const Place& station) {
  if (station.reserved_by == settings_.order_id) return raise("STATION_OURS");
  const auto it = std::find(station.waiting.begin(), station.waiting.end(), settings_.order_id);
  if (it == station.waiting.end()) return;  // not in the queue yet (the award's reply was quicker)
  report_place(1 + (it - station.waiting.begin()));
}

void OrderOrchestrator::report_place(long ahead) {
  if (ahead == ahead_) return;
  ahead_ = ahead;
  status("WAITING", "waiting for " + booking_.station() + ": " + std::to_string(ahead) + (ahead == 1 ? " order" : " orders") +
                        " ahead", 0);
}

void OrderOrchestrator::hire() {
  status("WAITING", booking_.station() + " is ours; hiring its arm, a mobile robot and buffers", 0);
  emit("CALL", booking_.arm(std::max(0.0, hold_at(booking_.station()))));
  for (const Data& give : booking_.gives(fetched_types())) emit("CALL", give);
  if (const auto robot = booking_.robot_when_ready(fetched_types())) emit("CALL", *robot);
}

void OrderOrchestrator::on_awarded(const Data& d) {
  const Booking::For what = booking_.awarded(d);
  const std::string& resource = get<std::string>(d, "resource_id");
  const long ahead = static_cast<long>(get<std::int64_t>(d, "ahead"));
  switch (what) {
    case Booking::For::host:
      if (ahead == 0) return raise("STATION_OURS");
      return raise("WAITS", {{"ahead", std::int64_t(ahead)}});
    case Booking::For::arm:
      emit("PREPARE", {{"resource_id", resource}});  // its commands' writer, matched by the first command
      arm_held_ = ahead == 0 || (places_.count(resource) && places_.at(resource).reserved_by == settings_.order_id);
      break;
    case Booking::For::robot:
      emit("PREPARE", {{"resource_id", resource}});
      break;
    case Booking::For::give:
      if (const auto robot = booking_.robot_when_ready(fetched_types())) emit("CALL", *robot);
      break;
  }
  start_physical_when_hired();
}

// --- quotes --------------------------------------------------------------------------------

void OrderOrchestrator::ask_for_quotes() {
  waiting_since_ = std::chrono::steady_clock::now();
  status("WAITING", "virtual assembly done; asking the cell's resources for quotes", 0);
  emit("ASK", booking_.host("", std::max(0.0, hold_at(virtual_station_))));
  for (const Data& give : booking_.gives(fetched_types())) emit("ASK", give);
}

void OrderOrchestrator::on_quoted(const Data& d) {
  switch (booking_.quoted(d)) {
    case Booking::For::host:
      station_wait_ = Booking::queue_of(d);
      break;
    case Booking::For::robot:
      robot_wait_ = Booking::queue_of(d);
      return quote_when_arm_known();
    default:
      break;
  }
  if (const auto robot = booking_.robot_when_ready(fetched_types())) emit("ASK", *robot);
}

// The arm's model needs its speed: its capability may come later than the station's. The
// station is the order's after its queue; the robot sets out once the station is the
// order's and its own earlier work is done.
void OrderOrchestrator::quote_when_arm_known() {
  if (booking_.robot().empty() || !arm_at(booking_.station()) || !knows_places()) return;
  const ModelledRun run = modelled(hired(), station_wait_, robot_wait_);
  raise("PRICED", {{"station", booking_.station()}, {"robot", booking_.robot()}, {"wait", run.start},
                   {"makespan", run.end}, {"robot_s", run.robot_s}});
}

// Also once the places of the station and the buffers are known: a resource's proposal may
// come before its capability (DDS matches each pair of endpoints on its own).
void OrderOrchestrator::start_physical_when_hired() {
  if (state() == Phase::hiring && !booking_.robot().empty() && !booking_.arm_resource().empty() && arm_held_ &&
      knows_places()) {
    raise("HIRED");
  }
}

bool OrderOrchestrator::knows_places() const {
  const auto& buffers = booking_.buffer_of();
  return places_.count(booking_.station()) &&
         std::all_of(buffers.begin(), buffers.end(), [this](const auto& b) { return places_.count(b.second) > 0; });
}

// --- scripts -------------------------------------------------------------------------------

std::vector<Trajectory> OrderOrchestrator::candidates(std::size_t step) const {
  std::vector<Trajectory> out;
  for (const auto& attempt : plan_.steps[step].failed) {
    // One that no grasp holds is not tried: cell-sim moves the part and the gripper as one.
    if (attempt.collision && attempt.collision->phase == "gripping") continue;
    out.push_back(attempt.trajectory);
  }
  out.push_back(plan_.steps[step].trajectory);
  return out;
}

std::string OrderOrchestrator::virtual_body(PartIndex part) const {
  return settings_.order_id + "/virtual/" + product_.product.parts()[part].name;
}

std::vector<std::string> OrderOrchestrator::fetched_types() const {
  std::vector<std::string> out;
  for (const auto& step : plan_.steps) {
    if (!inserts_unit(step)) out.push_back(short_type_name(product_.product.parts()[step.part].type));
  }
  return out;
}

Location OrderOrchestrator::location(const std::string& resource) const {
  const Place& p = places_.at(resource);
  return {p.position, p.dock};
}

Hired OrderOrchestrator::hired() const {
  Hired h{settings_.order_id, booking_.station(), booking_.arm_resource(), booking_.robot(), booking_.buffer_of(), {}};
  h.places[h.station] = location(h.station);
  for (const auto& [type, buffer] : h.buffer_of) h.places[buffer] = location(buffer);
  return h;
}

Data OrderOrchestrator::command(const std::string& resource, const std::string& operation, const std::string& part) {
  const std::string attempt = settings_.resume.attempt > 1 ? "r" + std::to_string(settings_.resume.attempt) + "/" : "";
  return {{"command_id", settings_.order_id + "/" + attempt + std::to_string(++command_count_) + "/" + operation},
          {"resource_id", resource}, {"order_id", settings_.order_id}, {"operation", operation}, {"part", part},
          {"award", booking_.award_of(resource)}};
}

// Virtual assembly of one candidate trajectory, all in cell-sim: the part and a gripper of
// the arm's shape in the order's scene, the gripper moved with the part, then backing out.
void OrderOrchestrator::add_candidate(std::size_t step, std::size_t candidate) {
  const PartIndex part = plan_.steps[step].part;
  const Trajectory t = candidates(step)[candidate];
  if (inserts_unit(plan_.steps[step])) return add_unit_candidate(step, t);
  const std::string body = virtual_body(part);
  const std::vector<std::string> gripper = virtual_gripper();
  const std::string& scene = settings_.order_id;
  const auto& w = t.waypoints;
  const MeshRef& mesh = *product_.product.parts()[part].mesh;
  // Where the robot puts it down, and carried from there as the cell's arm will carry it
  // (plan_physical): the carry is checked too, not only the trajectory.
  const Location& here = virtual_place_;
  const Pose start = geometry_.at(here, w.front().part), standing = geometry_.at_dock(here, part, start);
  const Pose grip = w.front().part.inverse() * w.front().gripper;
  actions_.push_back({Action::sim, sim_.spawn(body, pose_numbers({standing}), {0, 0, 0}, false, mesh.file.string(), scene,
                                              mesh.scale)});
  const auto boxes = fb::gripper_boxes(settings_.gripper, t.grasp.opening);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Vec3& h = boxes[i].half_extents;
    actions_.push_back({Action::sim, sim_.spawn(gripper[i], fb::pose_numbers(standing * grip * boxes[i].pose),
                                                {h.x(), h.y(), h.z()}, false, "", scene)});
  }
  spawned_.insert(body);
  spawned_.insert(gripper.begin(), gripper.end());
  const auto [holding, retreat, turning] = geometry_.carry(here, step, t, standing);
  const double v = settings_.arm_speed, omega = settings_.arm_angular_speed;
  // The palm leads; the fingers, the carriage and (while held) the part go with it; along a
  // helix at the end, the part turns into its mate's thread.
  std::vector<std::string> carried(gripper.begin() + 1, gripper.end());
  carried.push_back(body);
  const auto thread_start = holding.end() - static_cast<std::ptrdiff_t>(t.screw ? turning : 0);
  if (thread_start != holding.begin()) {
    actions_.push_back({Action::sim, sim_.move(gripper.front(), carried, pose_numbers({holding.begin(), thread_start}), v, omega),
                        true});
  }
  if (thread_start != holding.end()) {
    actions_.push_back({Action::sim, sim_.move(gripper.front(), carried, pose_numbers({thread_start, holding.end()}), v, omega,
                                               body, virtual_body(t.screw->mate)),
                        true});
  }
  carried.pop_back();
  if (!retreat.empty()) {
    actions_.push_back({Action::sim, sim_.move(gripper.front(), carried, pose_numbers(retreat), v, omega), true});
  }
  actions_.push_back({Action::sim, sim_.set_static(body, true)});
  for (const auto& g : gripper) {
    actions_.push_back({Action::sim, sim_.remove(g)});
    spawned_.erase(g);
  }
}

// A subassembly built aside in the order's scene, inserted whole along one candidate: its
// parts spawned where they stand aside (again after a collision), the gripper at the grasp on
// its base, up and over to the trajectory, along it, backing out.
void OrderOrchestrator::add_unit_candidate(std::size_t step, const Trajectory& t) {
  const PlanStep& unit_step = plan_.steps[step];
  const SubassemblyPlan* unit = geometry_.subassembly_of(unit_step);
  const std::string& scene = settings_.order_id;
  const Location& here = virtual_place_;
  std::vector<PartIndex> members{unit_step.part};
  members.insert(members.end(), unit_step.carried.begin(), unit_step.carried.end());
  for (PartIndex member : members) {
    const std::string body = virtual_body(member);
    const MeshRef& mesh = *product_.product.parts()[member].mesh;
    actions_.push_back({Action::sim, sim_.remove(body), false, true});
    actions_.push_back({Action::sim, sim_.spawn(body, pose_numbers({geometry_.at(here, geometry_.aside_pose(member, *unit))}),
                                                {0, 0, 0}, false, mesh.file.string(), scene, mesh.scale)});
    spawned_.insert(body);
  }
  const auto& w = t.waypoints;
  const Pose grip = w.front().part.inverse() * w.front().gripper;
  const Pose standing = geometry_.at(here, geometry_.aside_pose(unit_step.part, *unit));
  const std::vector<std::string> gripper = virtual_gripper();
  const auto boxes = fb::gripper_boxes(settings_.gripper, t.grasp.opening);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Vec3& h = boxes[i].half_extents;
    actions_.push_back({Action::sim, sim_.spawn(gripper[i], fb::pose_numbers(standing * grip * boxes[i].pose),
                                                {h.x(), h.y(), h.z()}, false, "", scene)});
  }
  spawned_.insert(gripper.begin(), gripper.end());
  const auto [holding, retreat, turning] = geometry_.carry(here, step, t, standing);
  const double v = settings_.arm_speed, omega = settings_.arm_angular_speed;
  std::vector<std::string> carried(gripper.begin() + 1, gripper.end());
  for (PartIndex member : members) carried.push_back(virtual_body(member));
  actions_.push_back({Action::sim, sim_.move(gripper.front(), carried, pose_numbers(holding), v, omega), true});
  carried.resize(gripper.size() - 1);
  if (!retreat.empty()) {
    actions_.push_back({Action::sim, sim_.move(gripper.front(), carried, pose_numbers(retreat), v, omega), true});
  }
  for (PartIndex member : members) actions_.push_back({Action::sim, sim_.set_static(virtual_body(member), true)});
  for (const auto& g : gripper) {
    actions_.push_back({Action::sim, sim_.remove(g)});
    spawned_.erase(g);
  }
}

std::vector<std::string> OrderOrchestrator::virtual_gripper() const {
  std::vector<std::string> out;
  for (const auto& box : fb::gripper_boxes(settings_.gripper, 0)) out.push_back(settings_.order_id + "/virtual/gripper-" + box.name);
  return out;
}

void OrderOrchestrator::on_collision(const std::string& reason) {
  const PartIndex part = plan_.steps[step_].part;
  const auto all = candidates(step_);
  const std::string& name = product_.product.parts()[part].name;
  emit("FINDING", {{"kind", std::string("collision")},
                   {"message", step_name(product_.product, plan_.steps[step_]) + " along '" + all[candidate_].label +
                                   "' in cell-sim: " + reason},
                   {"part", name}});
  actions_.clear();
  action_running_ = false;
  std::vector<std::string> left = virtual_gripper();
  left.push_back(virtual_body(part));
  for (PartIndex p : plan_.steps[step_].carried) left.push_back(virtual_body(p));
  for (const auto& body : left) {
    actions_.push_back({Action::sim, sim_.remove(body)});
    spawned_.erase(body);
  }
  if (++candidate_ >= all.size()) return back_to_sequence_planning();
  add_candidate(step_, candidate_);
  next_action();
}

void OrderOrchestrator::back_to_sequence_planning() {
  const PartIndex part = plan_.steps[step_].part;
  const std::string& name = product_.product.parts()[part].name;
  if (!settings_.resume.placed.empty() || !settings_.resume.aside.empty()) {
    // Parts stand on the station as the stored plan put them: another order from here would
    // be planned around parts that are not where it assumes.
    return fail("virtual assembly found no collision-free path in cell-sim for " + step_name(product_.product, plan_.steps[step_]) +
                " at step " + std::to_string(step_ + 1) + " of the plan its parts on " + settings_.resume.station +
                " were put in by; it is not planned otherwise around them");
  }
  if (!plan_.subassemblies.empty()) {
    // The planner takes steps already done only for a product without subassemblies.
    return fail("virtual assembly found no collision-free path in cell-sim for " + step_name(product_.product, plan_.steps[step_]) +
                " at step " + std::to_string(step_ + 1) + ", and a product with subassemblies is not planned again " +
                "from a part-way assembly; see the findings");
  }
  barred_.erase(barred_.upper_bound(step_), barred_.end());
  barred_[step_].insert(part);
  PlannerOptions options = settings_.replanning;
  options.gripper = settings_.gripper;
  options.given.assign(plan_.steps.begin(), plan_.steps.begin() + step_);  // validated already
  options.not_next = barred_[step_];
  SearchSequencePlanner sequence;
  const auto path = make_path_planner(plan_.path_planner);
  Plan replanned = plan_assembly(product_, sequence, *path, options);
  std::string barred;
  for (PartIndex p : barred_[step_]) barred += (barred.empty() ? "" : ", ") + product_.product.parts()[p].name;
  if (!replanned.complete) {
    return fail("virtual assembly found no collision-free path in cell-sim for " + name + ", and no other order of " +
                "the remaining parts works with " + barred + " not next at step " + std::to_string(step_ + 1));
  }
  const std::string& next = product_.product.parts()[replanned.steps[step_].part].name;
  emit("FINDING", {{"kind", std::string("backtrack")},
                   {"message", "no path in cell-sim for " + name + " at step " + std::to_string(step_ + 1) +
                                   "; planned again from the " + std::to_string(step_) + " parts in place, " + next +
                                   " next"},
                   {"part", name}});
  replanned.findings = plan_.findings;
  plan_ = std::move(replanned);
  holds_.clear();
  candidate_ = 0;
  add_candidate(step_, 0);
  next_action();
}

void OrderOrchestrator::plan_physical() {
  const auto& resume = settings_.resume;
  status("PHYSICAL_ASSEMBLY", "physical assembly at " + booking_.station() +
                                  (resume.used.empty() ? "" : " (taken up again: " + std::to_string(resume.placed.size()) +
                                                                  " parts in place, " +
                                                                  (resume.aside.empty() ? "" : std::to_string(resume.aside.size()) + " built aside, ") +
                                                                  std::to_string(resume.delivered.size()) + " at the dock)"),
         0);
  PhysicalScript script = physical_script(product_, plan_, geometry_, hired(), resume, sim_,
                                          [this](const std::string& resource, const std::string& operation,
                                                 const std::string& part) { return command(resource, operation, part); });
  actions_.insert(actions_.end(), script.actions.begin(), script.actions.end());
  fetch_of_ = std::move(script.fetch_of);
  placed_by_ = std::move(script.placed_by);
  delivered_.insert(script.delivered.begin(), script.delivered.end());
  spawned_.insert(script.spawned.begin(), script.spawned.end());
  next_action();
}

void OrderOrchestrator::ask_sim_again() {
  if (!sim_busy_) return;
  sim_busy_ = false;
  if (action_running_ && !actions_.empty() && actions_.front().kind == Action::sim) ask_sim(actions_.front().data);
}

void OrderOrchestrator::ask_sim(const Data& request) {
  asked_sim_at_ = std::chrono::steady_clock::now();
  emit("SIM", request);
}

bool OrderOrchestrator::sim_silent() const {
  return action_running_ && !sim_busy_ && !actions_.empty() && actions_.front().kind == Action::sim &&
         std::chrono::steady_clock::now() - asked_sim_at_ > settings_.wait_timeout;
}

void OrderOrchestrator::plan_cleanup() {
  waiting_since_ = std::chrono::steady_clock::now();
  unheard_.clear();  // what was not heard of by now is not wanted any more
  actions_.clear();
  action_running_ = false;
  for (const std::string& body : spawned_) actions_.push_back({Action::sim, sim_.remove(body)});
  spawned_.clear();
  next_action();
}

// --- running ------------------------------------------------------------------------------

void OrderOrchestrator::next_action() {
  while (!actions_.empty()) {
    Action& a = actions_.front();
    action_running_ = true;
    switch (a.kind) {
      case Action::sim:
        awaited_id_ = get<std::string>(a.data, "request_id");
        return ask_sim(a.data);
      case Action::command:
        awaited_id_ = get<std::string>(a.data, "command_id");
        return send_command(a.data);
      case Action::send_heard:
        awaited_id_ = get<std::string>(a.data, "command_id");
        return send_command(a.data);
      case Action::await_delivery:
        awaited_id_ = get<std::string>(a.data, "command_id");
        if (delivered_.count(awaited_id_)) {
          actions_.pop_front();
          continue;
        }
        return;
    }
  }
  action_running_ = false;
  if (state() == Phase::virtual_assembly) {
    if (step_ < plan_.steps.size()) {
      plan_.steps[step_].trajectory = candidates(step_)[candidate_];
      status("VIRTUAL_ASSEMBLY", "virtual assembly: " + std::to_string(step_ + 1) + " of " +
                                     std::to_string(plan_.steps.size()) + " steps",
             double(step_ + 1) / plan_.steps.size());
      candidate_ = 0;
      if (++step_ < plan_.steps.size()) {
        add_candidate(step_, 0);
        return next_action();
      }
      // The virtual product leaves cell-sim; then the order books a station for the real one.
      for (const std::string& body : spawned_) actions_.push_back({Action::sim, sim_.remove(body)});
      spawned_.clear();
      if (!actions_.empty()) return next_action();
    }
    return raise("VIRTUAL_DONE");
  }
  if (state() == Phase::physical) {
    status("PHYSICAL_ASSEMBLY", "physical assembly done", 1);
    return raise("PHYSICAL_DONE");
  }
  raise("CLEANED");
}

void OrderOrchestrator::action_done() {
  const Action& a = actions_.front();
  // Released, the part stands in the product (the arm recorded it so with the release).
  const auto placed = a.kind == Action::command ? placed_by_.find(get<std::string>(a.data, "command_id")) : placed_by_.end();
  if (state() == Phase::physical && placed != placed_by_.end()) {
    emit("PLACED", placed->second);
    placed_by_.erase(placed);
    const std::size_t left = placed_by_.size();
    status("PHYSICAL_ASSEMBLY", "physical assembly at " + booking_.station() + ": " +
                                    std::to_string(plan_.steps.size() - left) + " of " +
                                    std::to_string(plan_.steps.size()) + " steps",
           double(plan_.steps.size() - left) / plan_.steps.size());
  }
  actions_.pop_front();
  action_running_ = false;
  next_action();
}

void OrderOrchestrator::send_command(const Data& command) {
  const std::string& id = get<std::string>(command, "command_id");
  if (timeline_index_.emplace(id, timeline_.size()).second) {
    timeline_.push_back({fb::get_or<std::string>(command, "resource_id", ""), fb::get_or<std::string>(command, "operation", ""),
                         fb::get_or<std::string>(command, "part", ""), "", -1, -1});
  }
  unheard_[id] = {command, std::chrono::steady_clock::now()};
  emit("COMMAND", command);
}

void OrderOrchestrator::record(const Data& event) {
  const auto it = timeline_index_.find(get<std::string>(event, "command_id"));
  if (it == timeline_index_.end()) return;
  TimelineEntry& entry = timeline_[it->second];
  const double at = fb::get_or<double>(event, "sim_time", 0);
  const std::string& state = get<std::string>(event, "state");
  // A queued command runs from when it starts executing; one that never does, from its acceptance.
  if (entry.start < 0 || state == "executing") entry.start = at;
  if (state != "accepted" && state != "executing") {
    entry.end = at;
    entry.state = state;
  }
}

void OrderOrchestrator::resend_unheard() {
  const auto now = std::chrono::steady_clock::now();
  for (auto& [id, sent] : unheard_) {
    if (now - sent.at < settings_.resend_after) continue;
    sent.at = now;
    emit("COMMAND", sent.command);
  }
}

void OrderOrchestrator::fail(const std::string& reason) {
  if (!error_.empty()) return;
  error_ = reason;
  if (settings_.take_up_after_restart && state() == Phase::physical && fb::says_restarted(reason)) {
    take_up_ = true;
    return raise("TAKE_UP");
  }
  // The mobile robot need not fetch what will not be assembled.
  for (const auto& [fetch, part] : fetch_of_) {
    if (!delivered_.count(fetch)) emit("CANCEL", {{"command_id", fetch}});
  }
  raise("FAILED");
}

void OrderOrchestrator::finish() {
  for (const std::string& resource : booking_.to_release()) {
    emit("RELEASE", {{"order_id", settings_.order_id}, {"resource_id", resource}});
  }
  if (settings_.quote_only) {
    // Not feasible here is the quote's answer, which its caller gives.
  } else if (error_.empty()) {
    status("DONE", "assembled " + std::to_string(product_.product.parts().size()) + " parts at " + booking_.station(), 1);
  } else {
    status("FAILED", error_, 0);
  }
  emit("FINISHED", {{"complete", error_.empty()}, {"error", error_}, {"take_up", false}});
}

void OrderOrchestrator::status(const std::string& state, const std::string& message, double progress) {
  emit("STATUS", {{"state", state}, {"message", message}, {"progress", progress}});
}

}  // namespace twin
