#include "twin/orchestration/order_orchestrator.hpp"

#include <algorithm>

namespace twin {
namespace {

using fb::Data;
using fb::get;
using fb::Numbers;

Pose with_translation(Pose pose, double x, double y, double z) {
  pose.translation() = Vec3(x, y, z);
  return pose;
}

bool turns(const std::vector<Pose>& path) {
  for (const Pose& p : path) {
    if (!p.linear().isApprox(path.front().linear(), 1e-9)) return true;
  }
  return false;
}

}  // namespace

OrderOrchestrator::OrderOrchestrator(std::string name, const LoadedProduct& product, const Plan& plan,
                                     OrderSettings settings)
    : BasicBlock(std::move(name), "IDLE"), product_(product), plan_(plan), scene_(product),
      settings_(std::move(settings)), sim_(settings_.order_id) {
  declare_input("START");
  declare_input("TICK");
  declare_input("CAPABILITY", {"resource_id", "dock", "position"});
  declare_input("RESOURCE_GONE", {"resource_id"});
  declare_input("PROPOSAL", {"call_id", "resource_id"});
  declare_input("AWARD_REPLY", {"call_id", "resource_id", "confirmed", "reason"});
  declare_input("COMMAND_EVENT", {"command_id", "order_id", "state", "reason"});
  declare_input("SIM_REPLY", {"request_id", "ok", "error", "collided"});
  for (const char* out : {"CFP", "AWARD", "RELEASE", "COMMAND", "CANCEL", "SIM"}) declare_output(out);
  declare_output("STATUS", {"state", "message", "progress"});
  declare_output("FINDING", {"kind", "message", "part"});
  declare_output("FINISHED", {"complete", "error"});

  needs_ = {{"host", "", "", ""}, {"translate", "", "", ""}, {"fetch", "", "", ""}};
  std::set<std::string> types;
  for (const auto& step : plan_.steps) types.insert(short_type_name(product_.product.parts()[step.part].type));
  for (const auto& type : types) needs_.push_back({"give", type, "", ""});

  // Where resources are, in every state.
  for (const char* state : {"IDLE", "NEGOTIATING", "RUNNING", "ENDED"}) {
    transition(state, "CAPABILITY", state, [this](const Data& d) {
      docks_[get<std::string>(d, "resource_id")] = get<Numbers>(d, "dock");
      positions_[get<std::string>(d, "resource_id")] = get<Numbers>(d, "position");
    });
  }

  transition("IDLE", "START", "NEGOTIATING", [this](const Data&) {
    phase_started_ = std::chrono::steady_clock::now();
    status("NEGOTIATING", "calling for proposals", 0);
    call_for_proposals();
  });
  transition("NEGOTIATING", "TICK", "NEGOTIATING", [this](const Data&) {
    if (start_when_negotiated()) return;
    if (std::chrono::steady_clock::now() - phase_started_ < settings_.wait_timeout) return call_for_proposals();
    std::string missing;
    for (const Need& n : needs_) {
      if (n.awarded.empty()) missing += (missing.empty() ? "" : ", ") + n.operation + (n.part_type.empty() ? "" : " " + n.part_type);
    }
    std::string known;
    for (const auto& [id, dock] : docks_) known += (known.empty() ? "" : ", ") + id;
    fail("waited " + std::to_string(settings_.wait_timeout.count() / 1000) + " s and no resource offered: " + missing +
         " (resources seen: " + (known.empty() ? "none" : known) +
         "; is the cell up, are the parts in a buffer, is another order holding the station?)");
  });
  transition("NEGOTIATING", "PROPOSAL", "NEGOTIATING", [this](const Data& d) {
    for (Need& n : needs_) {
      if (settings_.order_id + "/" + n.operation + "/" + n.part_type != get<std::string>(d, "call_id")) continue;
      if (!n.awarded.empty() || !n.pending.empty()) return;
      n.pending = get<std::string>(d, "resource_id");
      emit("AWARD", {{"call_id", get<std::string>(d, "call_id")}, {"resource_id", n.pending},
                     {"order_id", settings_.order_id}, {"lease", settings_.award_lease_s}});
    }
  });
  transition("NEGOTIATING", "AWARD_REPLY", "NEGOTIATING", [this](const Data& d) {
    for (Need& n : needs_) {
      if (settings_.order_id + "/" + n.operation + "/" + n.part_type != get<std::string>(d, "call_id")) continue;
      if (n.pending != get<std::string>(d, "resource_id")) return;
      if (get<bool>(d, "confirmed")) n.awarded = n.pending;
      n.pending.clear();  // refused: called again at the next tick
    }
    start_when_negotiated();
  });
  transition("NEGOTIATING", "RESOURCE_GONE", "NEGOTIATING", [this](const Data& d) {
    for (Need& n : needs_) {
      if (n.pending == get<std::string>(d, "resource_id")) n.pending.clear();
      if (n.awarded == get<std::string>(d, "resource_id")) n.awarded.clear();
    }
  });

  transition("RUNNING", "SIM_REPLY", "RUNNING", [this](const Data& d) {
    if (!action_running_ || get<std::string>(d, "request_id") != awaited_id_) return;
    if (get<bool>(d, "ok") || phase_ == "cleanup") return action_done();
    fail("cell-sim refused: " + get<std::string>(d, "error"));
  });
  transition("RUNNING", "COMMAND_EVENT", "RUNNING", [this](const Data& d) {
    if (get<std::string>(d, "order_id") != settings_.order_id) return;
    const std::string& id = get<std::string>(d, "command_id");
    const std::string& state = get<std::string>(d, "state");
    if (const auto fetch = fetch_of_.find(id); fetch != fetch_of_.end()) {
      if (state == "succeeded") {
        delivered_.insert(id);
        if (action_running_ && actions_.front().kind == Action::await_delivery && awaited_id_ == id) action_done();
      } else if (state == "aborted" && phase_ != "cleanup") {
        fail("fetching " + product_.product.parts()[fetch->second].name + " failed: " + get<std::string>(d, "reason"));
      }
      return;
    }
    if (!action_running_ || id != awaited_id_) return;
    if (state == "succeeded") return action_done();
    if (state != "aborted") return;
    if (phase_ == "cleanup") return action_done();
    if (actions_.front().retry_on_collision) return on_collision(get<std::string>(d, "reason"));
    fail(fb::get_or<std::string>(d, "resource_id", "") + " " + get<std::string>(actions_.front().data, "operation") +
         " failed: " + get<std::string>(d, "reason"));
  });
  transition("RUNNING", "RESOURCE_GONE", "RUNNING", [this](const Data& d) {
    const std::string& id = get<std::string>(d, "resource_id");
    const bool ours = std::any_of(needs_.begin(), needs_.end(), [&](const Need& n) { return n.awarded == id; });
    if (ours && phase_ != "cleanup") fail(id + " disappeared (its liveliness lease ran out)");
  });
  transition("RUNNING", "TICK", "RUNNING", [this](const Data&) {
    if (phase_ == "cleanup" && std::chrono::steady_clock::now() - phase_started_ > settings_.cleanup_timeout) finish();
  });
}

// --- negotiation ---------------------------------------------------------------------------

void OrderOrchestrator::call_for_proposals() {
  for (const Need& n : needs_) {
    if (!n.awarded.empty() || !n.pending.empty()) continue;
    emit("CFP", {{"call_id", settings_.order_id + "/" + n.operation + "/" + n.part_type},
                 {"order_id", settings_.order_id}, {"operation", n.operation}, {"part_type", n.part_type}});
  }
}

// Every need awarded, and where each awarded resource hands parts over known.
bool OrderOrchestrator::negotiated() const {
  return std::all_of(needs_.begin(), needs_.end(), [this](const Need& n) { return docks_.count(n.awarded) > 0; });
}

const std::string& OrderOrchestrator::awarded(const std::string& operation, const std::string& part_type) const {
  for (const Need& n : needs_) {
    if (n.operation == operation && n.part_type == part_type) return n.awarded;
  }
  throw std::logic_error("no need " + operation + " " + part_type);
}

bool OrderOrchestrator::start_when_negotiated() {
  if (!negotiated()) return false;
  enter("RUNNING");
  phase_started_ = std::chrono::steady_clock::now();
  status("VIRTUAL_ASSEMBLY", "virtual assembly in cell-sim", 0);
  step_ = candidate_ = 0;
  if (plan_.steps.empty()) {
    plan_physical();
  } else {
    add_candidate(0, 0);
    next_action();
  }
  return true;
}

// --- scripts -------------------------------------------------------------------------------

std::vector<Trajectory> OrderOrchestrator::candidates(std::size_t step) const {
  std::vector<Trajectory> out;
  for (const auto& attempt : plan_.steps[step].failed) out.push_back(attempt.trajectory);
  out.push_back(plan_.steps[step].trajectory);
  return out;
}

Pose OrderOrchestrator::at_station(const Pose& pose) const {
  const Numbers& p = positions_.at(awarded("host"));
  Pose offset = Pose::Identity();
  offset.translation() = Vec3(p[0], p[1], p[2]);
  return offset * pose;
}

Numbers OrderOrchestrator::pose_numbers(const std::vector<Pose>& poses) const {
  Numbers out;
  for (const Pose& p : poses) {
    const Quat q(p.linear());
    out.insert(out.end(), {p.translation().x(), p.translation().y(), p.translation().z(), q.w(), q.x(), q.y(), q.z()});
  }
  return out;
}

std::string OrderOrchestrator::virtual_body(PartIndex part) const {
  return settings_.order_id + "/virtual/" + product_.product.parts()[part].name;
}

std::string OrderOrchestrator::physical_body(PartIndex part) const {
  return settings_.order_id + "/" + product_.product.parts()[part].name;
}

Data OrderOrchestrator::command(const std::string& resource, const std::string& operation, const std::string& part) {
  return {{"command_id", settings_.order_id + "/" + std::to_string(++command_count_) + "/" + operation},
          {"resource_id", resource}, {"order_id", settings_.order_id}, {"operation", operation}, {"part", part}};
}

// Grip, move along the pads' poses while holding, release, back out, connect.
void OrderOrchestrator::add_trajectory_moves(const std::string& body, const std::vector<Pose>& holding,
                                             const std::vector<Pose>& retreat, bool retry) {
  const std::string& arm = awarded("translate");
  Data move = command(arm, turns(holding) ? "rotate" : "translate", body);
  move["path"] = pose_numbers(holding);
  actions_.push_back({Action::command, move, retry});
  actions_.push_back({Action::command, command(arm, "release", body)});
  Data back = command(arm, "translate", body);
  back["path"] = pose_numbers(retreat);
  actions_.push_back({Action::command, back, retry});
  actions_.push_back({Action::command, command(arm, "connect", body)});
}

void OrderOrchestrator::add_candidate(std::size_t step, std::size_t candidate) {
  phase_ = "virtual";
  const PartIndex part = plan_.steps[step].part;
  const Trajectory t = candidates(step)[candidate];
  const std::string body = virtual_body(part);
  const auto& w = t.waypoints;
  actions_.push_back({Action::sim, sim_.spawn(body, pose_numbers({at_station(w.front().part)}), {0, 0, 0}, false,
                                              product_.product.parts()[part].mesh->file.string())});
  spawned_.insert(body);
  Data grip = command(awarded("translate"), "grip", body);
  grip["path"] = pose_numbers({at_station(w.front().gripper)});
  const Vec3 pad = scene_.pad_half_extents(part, t.grip_direction);
  grip["size"] = Numbers{pad.x(), pad.y(), pad.z()};
  grip["direction"] = Numbers{t.grip_direction.x(), t.grip_direction.y(), t.grip_direction.z()};
  actions_.push_back({Action::command, grip});
  std::vector<Pose> holding, retreat;
  for (std::size_t i = 1; i < w.size(); ++i) (w[i].holding ? holding : retreat).push_back(at_station(w[i].gripper));
  add_trajectory_moves(body, holding, retreat, true);
}

void OrderOrchestrator::on_collision(const std::string& reason) {
  const PartIndex part = plan_.steps[step_].part;
  const auto all = candidates(step_);
  const std::string& name = product_.product.parts()[part].name;
  emit("FINDING", {{"kind", std::string("collision")},
                   {"message", name + " along '" + all[candidate_].label + "' in cell-sim: " + reason},
                   {"part", name}});
  actions_.clear();
  action_running_ = false;
  const std::string body = virtual_body(part);
  actions_.push_back({Action::command, command(awarded("translate"), "release", body)});
  actions_.push_back({Action::sim, sim_.remove(body)});
  spawned_.erase(body);
  if (++candidate_ >= all.size()) return back_to_sequence_planning();
  add_candidate(step_, candidate_);
  next_action();
}

void OrderOrchestrator::back_to_sequence_planning() {
  const PartIndex part = plan_.steps[step_].part;
  const std::string& name = product_.product.parts()[part].name;
  barred_.erase(barred_.upper_bound(step_), barred_.end());
  barred_[step_].insert(part);
  PlannerOptions options;
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
  candidate_ = 0;
  add_candidate(step_, 0);
  next_action();
}

void OrderOrchestrator::plan_physical() {
  phase_ = "physical";
  phase_started_ = std::chrono::steady_clock::now();
  status("PHYSICAL_ASSEMBLY", "virtual assembly done; physical assembly", 0);
  for (const std::string& body : std::set<std::string>(spawned_)) {
    actions_.push_back({Action::sim, sim_.remove(body)});
    spawned_.erase(body);
  }
  const std::string& station = awarded("host");
  const std::string& robot = awarded("fetch");
  const std::string& arm = awarded("translate");
  const Numbers& dock = docks_.at(station);
  std::vector<std::string> fetches;
  for (const auto& step : plan_.steps) {
    const auto& part = product_.product.parts()[step.part];
    const std::string type = short_type_name(part.type);
    const std::string& buffer = awarded("give", type);
    const Numbers& source = docks_.at(buffer);
    const Pose final_pose = at_station(part.final_pose);
    const std::string body = physical_body(step.part);
    const Pose in_buffer = with_translation(final_pose, source[0], final_pose.translation().y(), source[2]);
    actions_.push_back({Action::sim, sim_.spawn(body, pose_numbers({in_buffer}), {0, 0, 0}, false, part.mesh->file.string())});
    spawned_.insert(body);
    Data fetch = command(robot, "fetch", body);
    fetch["part_type"] = type;
    fetch["source"] = buffer;
    fetch["destination"] = station;
    fetch_of_[get<std::string>(fetch, "command_id")] = step.part;
    fetches.push_back(get<std::string>(fetch, "command_id"));
    actions_.push_back({Action::send_only, fetch});
  }
  for (std::size_t i = 0; i < plan_.steps.size(); ++i) {
    const PartIndex part = plan_.steps[i].part;
    const Trajectory& t = plan_.steps[i].trajectory;
    const auto& w = t.waypoints;
    const std::string body = physical_body(part);
    actions_.push_back({Action::await_delivery, {{"command_id", fetches[i]}}});
    // Delivered at the dock; carried up, over to where the trajectory starts, then along it.
    const Pose grip = w.front().part.inverse() * w.front().gripper;
    const Pose start = at_station(w.front().part);
    const Pose delivered = with_translation(start, dock[0], at_station(product_.product.parts()[part].final_pose).translation().y(), dock[2]);
    const double safe = std::max(delivered.translation().y(), start.translation().y());
    std::vector<Pose> part_path = {
        with_translation(delivered, dock[0], safe, dock[2]),
        with_translation(start, start.translation().x(), safe, start.translation().z()), start};
    Data take = command(arm, "grip", body);
    take["path"] = pose_numbers({delivered * grip});
    const Vec3 pad = scene_.pad_half_extents(part, t.grip_direction);
    take["size"] = Numbers{pad.x(), pad.y(), pad.z()};
    take["direction"] = Numbers{t.grip_direction.x(), t.grip_direction.y(), t.grip_direction.z()};
    actions_.push_back({Action::command, take});
    std::vector<Pose> holding, retreat;
    for (const Pose& p : part_path) holding.push_back(p * grip);
    for (std::size_t k = 1; k < w.size(); ++k) (w[k].holding ? holding : retreat).push_back(at_station(w[k].gripper));
    add_trajectory_moves(body, holding, retreat, false);
  }
  next_action();
}

void OrderOrchestrator::plan_cleanup() {
  phase_ = "cleanup";
  phase_started_ = std::chrono::steady_clock::now();
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
        return emit("SIM", a.data);
      case Action::command:
        awaited_id_ = get<std::string>(a.data, "command_id");
        return emit("COMMAND", a.data);
      case Action::send_only:
        emit("COMMAND", a.data);
        actions_.pop_front();
        continue;
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
  if (phase_ == "virtual") {
    plan_.steps[step_].trajectory = candidates(step_)[candidate_];
    status("VIRTUAL_ASSEMBLY", "virtual assembly: " + std::to_string(step_ + 1) + " of " +
                                   std::to_string(plan_.steps.size()) + " parts",
           double(step_ + 1) / plan_.steps.size());
    candidate_ = 0;
    if (++step_ < plan_.steps.size()) {
      add_candidate(step_, 0);
      return next_action();
    }
    return plan_physical();
  }
  if (phase_ == "physical") {
    status("PHYSICAL_ASSEMBLY", "physical assembly done", 1);
    return plan_cleanup();
  }
  finish();
}

void OrderOrchestrator::action_done() {
  const Action& a = actions_.front();
  if (phase_ == "physical" && a.kind == Action::command && get<std::string>(a.data, "operation") == "connect") {
    const std::size_t done = std::count_if(actions_.begin(), actions_.end(), [](const Action& x) {
      return x.kind == Action::await_delivery;
    });
    status("PHYSICAL_ASSEMBLY", "physical assembly: " + std::to_string(plan_.steps.size() - done) + " of " +
                                    std::to_string(plan_.steps.size()) + " parts",
           double(plan_.steps.size() - done) / plan_.steps.size());
  }
  actions_.pop_front();
  action_running_ = false;
  next_action();
}

void OrderOrchestrator::fail(const std::string& reason) {
  if (!error_.empty()) return;
  error_ = reason;
  // The mobile robot need not fetch what will not be assembled.
  for (const auto& [fetch, part] : fetch_of_) {
    if (!delivered_.count(fetch)) emit("CANCEL", {{"command_id", fetch}});
  }
  if (state() == "NEGOTIATING" || state() == "IDLE") return finish();
  enter("RUNNING");
  plan_cleanup();
}

void OrderOrchestrator::finish() {
  enter("ENDED");
  for (const Need& n : needs_) {
    if (!n.awarded.empty() && n.operation != "give") {
      emit("RELEASE", {{"order_id", settings_.order_id}, {"resource_id", n.awarded}});
    }
  }
  if (error_.empty()) {
    status("DONE", "assembled " + std::to_string(plan_.steps.size()) + " parts", 1);
  } else {
    status("FAILED", error_, 0);
  }
  emit("FINISHED", {{"complete", error_.empty()}, {"error", error_}});
}

void OrderOrchestrator::status(const std::string& state, const std::string& message, double progress) {
  emit("STATUS", {{"state", state}, {"message", message}, {"progress", progress}});
}

}  // namespace twin
