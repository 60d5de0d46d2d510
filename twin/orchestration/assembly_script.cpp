#include "twin/orchestration/assembly_script.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

#include "services/node/gripper.hpp"
#include "twin/orchestration/booking.hpp"
#include "twin/planning/subassembly_planner.hpp"

namespace twin {
namespace {

using fb::Data;
using fb::get;
using fb::Numbers;


Pose with_translation(Pose pose, double x, double y, double z) {
  pose.translation() = Vec3(x, y, z);
  return pose;
}

// A part (or a subassembly) standing at `from` carried to where its trajectory starts: up to
// the higher of the two (at least `least`), over, then down to the start.
std::vector<Pose> lift_over(const Pose& from, const Pose& start, double least) {
  const double safe = std::max({from.translation().y(), start.translation().y(), least});
  return {with_translation(from, from.translation().x(), safe, from.translation().z()),
          with_translation(start, start.translation().x(), safe, start.translation().z()), start};
}

// The body that stands for a step's part among `bodies`: its first one, or one a later twin
// fetched anew ("<body>/rN").
const std::string* body_in(const std::set<std::string>& bodies, const std::string& body) {
  for (const std::string& b : bodies) {
    if (b == body) return &b;
    if (b.size() > body.size() + 2 && b.compare(0, body.size(), body) == 0 && b.compare(body.size(), 2, "/r") == 0 &&
        std::all_of(b.begin() + body.size() + 2, b.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); })) {
      return &b;
    }
  }
  return nullptr;
}

// After the grip: move along the gripper's poses while holding, release, back out, connect.
// A step that holds its part (PlanStep::hold: it stands only once fastened) connects before
// the release, the gripper still on the part.
void add_arm_moves(PhysicalScript& script, const Hired& hired, const CommandMaker& command,
                   const std::vector<std::string>& bodies, const Carry& carry, const std::string& aside, bool hold,
                   const Screw* screw, const std::string& into) {
  auto& actions = script.actions;
  const std::size_t turning = screw ? carry.turning : 0;
  const std::vector<Pose> holding(carry.holding.begin(), carry.holding.end() - static_cast<std::ptrdiff_t>(turning));
  const bool turns = std::any_of(holding.begin(), holding.end(),
                                 [&](const Pose& p) { return !p.linear().isApprox(holding.front().linear(), 1e-9); });
  if (!holding.empty()) {
    Data move = command(hired.arm, turns ? "rotate" : "translate", bodies.front());
    move["path"] = pose_numbers(holding);
    actions.push_back({ScriptAction::command, move});
  }
  if (turning > 0) {
    Data turn = command(hired.arm, "screw", bodies.front());
    turn["path"] = pose_numbers({carry.holding.end() - static_cast<std::ptrdiff_t>(turning), carry.holding.end()});
    turn["turns"] = screw->turns;
    turn["pitch"] = screw->pitch;
    turn["destination"] = into;
    actions.push_back({ScriptAction::command, turn});
  }
  const auto connect = [&] {
    for (const auto& body : bodies) actions.push_back({ScriptAction::command, command(hired.arm, "connect", body)});
  };
  if (hold) connect();
  Data release = command(hired.arm, "release", bodies.front());
  // The state records where the parts go with the release (CellStore::release).
  release["destination"] = aside.empty() ? std::string("product") : "aside:" + aside;
  script.placed_by[get<std::string>(release, "command_id")] = {{"part", fb::join_names(bodies)}, {"aside", aside}};
  actions.push_back({ScriptAction::command, release});
  Data back = command(hired.arm, "translate", bodies.front());
  back["path"] = pose_numbers(carry.retreat);
  actions.push_back({ScriptAction::command, back});
  if (!hold) connect();
}

}  // namespace

Numbers pose_numbers(const std::vector<Pose>& poses) {
  Numbers out;
  for (const Pose& p : poses) {
    const Numbers seven = fb::pose_numbers(p);
    out.insert(out.end(), seven.begin(), seven.end());
  }
  return out;
}

Pose CarryGeometry::at(const Location& station, const Pose& pose) const {
  const Numbers& p = station.position;
  Pose offset = Pose::Identity();
  offset.translation() = Vec3(p[0], p[1], p[2]);
  return offset * pose;
}

Pose CarryGeometry::at_dock(const Location& station, PartIndex part, const Pose& start) const {
  const double height = at(station, product_.product.parts()[part].final_pose).translation().y();
  return with_translation(start, station.dock[0], height, station.dock[2]);
}

Carry CarryGeometry::carry(const Location& station, std::size_t index, const Trajectory& t, const Pose& standing) const {
  const auto& w = t.waypoints;
  const Pose grip = w.front().part.inverse() * w.front().gripper;
  const double least = carry_height(index, w.front().part) + station.position[1];
  Carry c;
  for (const Pose& p : lift_over(standing, at(station, w.front().part), least)) c.holding.push_back(p * grip);
  for (std::size_t i = 1; i < w.size(); ++i) {
    (w[i].holding ? c.holding : c.retreat).push_back(at(station, w[i].gripper));
    if (w[i].phase == "screw") ++c.turning;
  }
  return c;
}

const SubassemblyPlan* CarryGeometry::subassembly_of(const PlanStep& step) const {
  for (const auto& unit : plan_.subassemblies) {
    if (unit.name == step.subassembly) return &unit;
  }
  return nullptr;
}

double CarryGeometry::carry_height(std::size_t index, const Pose& pose) const {
  constexpr double kClearance = 0.02;  // m
  const PlanStep& step = plan_.steps[index];
  double top = -std::numeric_limits<double>::infinity();
  for (const auto& unit : plan_.subassemblies) top = std::max(top, final_bounds(product_, unit.members).max().y() + unit.aside.y());
  // The parts in the product already (a carry at the height its trajectory starts went
  // through the tower it was to go on).
  for (std::size_t i = 0; i < index; ++i) {
    if (!plan_.steps[i].subassembly.empty()) continue;  // built aside: the asides' tops above
    std::vector<PartIndex> in_place{plan_.steps[i].part};
    in_place.insert(in_place.end(), plan_.steps[i].carried.begin(), plan_.steps[i].carried.end());
    top = std::max(top, final_bounds(product_, in_place).max().y());
  }
  if (!std::isfinite(top)) return top;
  // How far the moving parts reach below `pose`, turned as it is.
  const Pose& base = product_.product.parts()[step.part].final_pose;
  std::vector<PartIndex> moving{step.part};
  moving.insert(moving.end(), step.carried.begin(), step.carried.end());
  Pose turned = Pose::Identity();
  turned.linear() = pose.rotation();
  double below = 0;
  for (PartIndex p : moving) {
    const Pose offset = turned * base.inverse() * product_.product.parts()[p].final_pose;
    for (const auto& v : product_.meshes[p]->vertices) below = std::min(below, (offset * v).y());
  }
  return top + kClearance - below;
}

Pose CarryGeometry::aside_pose(PartIndex part, const SubassemblyPlan& unit) const {
  Pose pose = product_.product.parts()[part].final_pose;
  pose.pretranslate(unit.aside);
  return pose;
}

PhysicalScript physical_script(const LoadedProduct& product, const Plan& plan, const CarryGeometry& geometry,
                               const Hired& hired, const Resume& resume, fb::SimRequests& sim,
                               const CommandMaker& command) {
  PhysicalScript script;
  auto& actions = script.actions;
  const Location& station = hired.places.at(hired.station);
  // A part set aside (or given back) by the earlier attempt leaves the scene; a new one comes.
  for (const auto& body : resume.used) {
    if (!resume.placed.count(body) && !resume.delivered.count(body)) {
      actions.push_back({ScriptAction::sim, sim.remove(body), false, true});
    }
  }
  std::vector<std::string> fetches, bodies;  // per step to do: what to await ("": nothing), its body
  std::vector<std::size_t> steps;              // the steps to do
  std::map<PartIndex, std::string> body_of;
  for (std::size_t i = 0; i < plan.steps.size(); ++i) {
    const auto& step = plan.steps[i];
    if (inserts_unit(step)) {  // its parts were built aside by the steps before
      if (!body_in(resume.placed, body_of.at(step.part))) {
        steps.push_back(i);
        fetches.emplace_back();
        bodies.push_back(body_of.at(step.part));
      }
      continue;
    }
    const auto& part = product.product.parts()[step.part];
    const std::string type = short_type_name(part.type);
    const Pose final_pose = geometry.at(station, part.final_pose);
    std::string body = hired.order + "/" + part.name;
    const std::string mesh = part.mesh->file.string();
    const double scale = part.mesh->scale;
    const std::string* placed = body_in(resume.placed, body);  // done: it stands in the product
    const SubassemblyPlan* unit = geometry.subassembly_of(step);
    // Done: it stands in its subassembly aside (a state that says so of a part this plan
    // builds into none is not taken: the part is fetched anew).
    const std::string* aside = unit ? body_in(resume.aside, body) : nullptr;
    if (placed || aside) {
      body = placed ? *placed : *aside;
      const Pose where = placed ? final_pose : geometry.at(station, geometry.aside_pose(step.part, *unit));
      actions.push_back({ScriptAction::sim, sim.spawn(body, pose_numbers({where}), {0, 0, 0}, true, mesh, "", scale)});
      script.spawned.insert(body);
      body_of[step.part] = body;
      continue;
    }
    steps.push_back(i);
    if (const std::string* delivered = body_in(resume.delivered, body)) {  // at the dock, where a robot put it down
      body = *delivered;
      const Pose down = geometry.at_dock(station, step.part, geometry.at(station, step.trajectory.waypoints.front().part));
      actions.push_back({ScriptAction::sim, sim.spawn(body, pose_numbers({down}), {0, 0, 0}, false, mesh, "", scale)});
      script.spawned.insert(body);
      fetches.push_back("delivered/" + body);
      script.delivered.insert(fetches.back());
      bodies.push_back(body);
      body_of[step.part] = body;
      continue;
    }
    if (body_in(resume.used, body)) body += "/r" + std::to_string(resume.attempt);  // the one before was set aside
    const std::string& buffer = hired.buffer_of.at(type);
    const Numbers& source = hired.places.at(buffer).dock;
    const Pose in_buffer = with_translation(final_pose, source[0], final_pose.translation().y(), source[2]);
    actions.push_back({ScriptAction::sim, sim.spawn(body, pose_numbers({in_buffer}), {0, 0, 0}, false, mesh, "", scale)});
    script.spawned.insert(body);
    bodies.push_back(body);
    body_of[step.part] = body;
    Data fetch = command(hired.robot, "fetch", body);
    fetch["part_type"] = type;
    fetch["source"] = buffer;
    fetch["destination"] = hired.station;
    fetch["source_award"] = Booking::give_call_id(hired.order, type);
    script.fetch_of[get<std::string>(fetch, "command_id")] = step.part;
    fetches.push_back(get<std::string>(fetch, "command_id"));
    actions.push_back({ScriptAction::send_heard, fetch});
  }
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const PlanStep& step = plan.steps[steps[k]];
    const Trajectory& t = step.trajectory;
    const auto& w = t.waypoints;
    const SubassemblyPlan* unit = geometry.subassembly_of(step);
    std::vector<std::string> moved{bodies[k]};
    for (PartIndex p : step.carried) moved.push_back(body_of.at(p));
    const Pose grip = w.front().part.inverse() * w.front().gripper;
    const Pose start = geometry.at(station, w.front().part);
    Pose standing;  // where the arm grips it
    if (inserts_unit(step)) {
      // Built aside and connected there: movable again, gripped by its base.
      standing = geometry.at(station, geometry.aside_pose(step.part, *unit));
      for (const auto& body : moved) actions.push_back({ScriptAction::command, command(hired.arm, "disconnect", body)});
    } else {
      actions.push_back({ScriptAction::await_delivery, {{"command_id", fetches[k]}}});
      standing = geometry.at_dock(station, step.part, start);
    }
    // Carried up from where it stands, over to where the trajectory starts, then along it.
    Data take = command(hired.arm, "grip", bodies[k]);
    take["path"] = pose_numbers({standing * grip});
    take["opening"] = t.grasp.opening;
    take["carried"] = fb::join_names({moved.begin() + 1, moved.end()});
    actions.push_back({ScriptAction::command, take});
    const auto into = t.screw ? body_of.find(t.screw->mate) : body_of.end();
    add_arm_moves(script, hired, command, moved, geometry.carry(station, steps[k], t, standing),
                  unit && !inserts_unit(step) ? unit->name : "", step.hold, into != body_of.end() ? &*t.screw : nullptr,
                  into != body_of.end() ? into->second : "");
  }
  return script;
}

}  // namespace twin
