#include "services/station/arm_block.hpp"

#include <set>
#include <sstream>

#include "services/state/cell_store.hpp"

namespace fb {
namespace {
// A subassembly's members: cell-sim moves at most 64 bodies with one, and the arm's palm
// carries its fingers, its carriage and the gripped part besides.
constexpr std::size_t kMaxCarried = 60;
constexpr double kPi = 3.14159265358979323846;
constexpr double kMostTurns = 1000;  // a screw's: an M3 screw 500 mm long
constexpr double kMostPitch = 0.05;  // m: far coarser than any thread
}  // namespace

ArmBlock::ArmBlock(std::string name, std::string id, ArmSettings settings)
    : DeviceBlock(std::move(name), id, {"grip", "translate", "rotate", "screw", "release", "connect", "disconnect"}),
      settings_(settings), sim_(id) {
  declare_input("SIM_REPLY", {"request_id", "ok"});
  declare_output("SIM", {"request_id", "kind", "body_id"});

  const auto op = [](const char* name) {
    return [name](const Data& d) { return get<std::string>(d, "operation") == name; };
  };
  const auto mine = [this](const Data& d) {
    return get<std::string>(d, "request_id").rfind(resource_id() + "/sim/", 0) == 0;
  };

  const auto is_grasp = [](const Data& d) { return get<Numbers>(d, "path").size() == 7; };
  transition("READY", "START", "WAITING", [this](const Data& d) { grip(d); },
             [op, is_grasp](const Data& d) { return op("grip")(d) && is_grasp(d); });
  transition("READY", "START", "READY", [this](const Data&) {
    emit("FAIL", {{"reason", std::string("grip needs one gripper pose and an opening")}});
  }, op("grip"));
  // A screw turns the held part into the thread of `destination`: it may go into that body by
  // the thread's overlap, nothing else may.
  transition("READY", "START", "READY", [this](const Data&) {
    emit("FAIL", {{"reason", std::string("screw: the arm holds no part to turn")}});
  }, [this, op](const Data& d) { return op("screw")(d) && held_.empty(); });
  for (const char* motion : {"translate", "rotate", "screw"}) {
    transition("READY", "START", "MOVING", [this](const Data& d) {
      sim_.act_for(get_or<std::string>(d, "order_id", ""));
      std::vector<std::string> carried = gripper_bodies();
      carried.erase(carried.begin());  // the palm leads
      if (!held_.empty()) {
        const auto held = held_bodies();
        carried.insert(carried.end(), held.begin(), held.end());
      }
      awaited_ = 1;
      const bool screw = get<std::string>(d, "operation") == "screw";
      request(sim_.move(gripper_bodies().front(), carried, get<Numbers>(d, "path"), settings_.speed, settings_.angular_speed,
                        screw ? held_ : "", screw ? get<std::string>(d, "destination") : ""));
    }, op(motion));
  }
  // `destination`: what the part goes into, for the cell's state (CellStore::release).
  transition("READY", "START", "READY", [this](const Data& d) {
    if (store() && !held_.empty()) store()->release(held_order_, held_bodies(), get_or<std::string>(d, "destination", ""));
    held_.clear();
    carried_.clear();
    emit("DONE");
  }, op("release"));
  for (const char* joining : {"connect", "disconnect"}) {
    const bool is_static = std::string(joining) == "connect";
    transition("READY", "START", "WAITING", [this, is_static](const Data& d) {
      error_.clear();
      awaited_ = 1;
      sim_.act_for(get_or<std::string>(d, "order_id", ""));
      request(sim_.set_static(get<std::string>(d, "part"), is_static));
    }, op(joining));
  }
  // A motion ends with cell-sim's reply: where it stopped and why.
  transition("MOVING", "SIM_REPLY", "READY", [this](const Data& reply) {
    std::string failure;
    Data outcome = move_outcome(reply, failure);
    emit(failure.empty() ? "DONE" : "FAIL", std::move(outcome));
  }, [this](const Data& d) { return sim_.answers_last(d); });
  // Other commands end when all their requests are answered.
  const auto note_error = [this](const Data& reply) {
    if (!get<bool>(reply, "ok") && error_.empty()) error_ = get<std::string>(reply, "error");
  };
  transition("WAITING", "SIM_REPLY", "READY", [this, note_error](const Data& reply) {
    note_error(reply);
    awaited_ = 0;
    if (error_.empty()) return emit("DONE");
    emit("FAIL", {{"reason", error_}});
  }, [this, mine](const Data& d) { return mine(d) && awaited_ == 1; });
  transition("WAITING", "SIM_REPLY", "WAITING", [this, note_error](const Data& reply) {
    note_error(reply);
    --awaited_;
  }, mine);
}

// A grip is one gripper pose and an opening the gripper has; a motion, a path.
void ArmBlock::check(const Data& command, SampleCheck& c) const {
  const std::string& operation = get<std::string>(command, "operation");
  if (operation == "grip") {
    c.poses("path", 1, 1).at_least("opening", 0);
    const double opening = get_or<double>(command, "opening", 0);
    std::ostringstream why;
    why << "opening: " << opening << " m is wider than the gripper opens (" << settings_.gripper.max_opening << " m)";
    c.require(!(opening > settings_.gripper.max_opening), why.str());
    c.names("carried", kMaxCarried);
    if (!c.ok()) return;
    const auto carried = split_names(get_or<std::string>(command, "carried", ""));
    const std::string part = get_or<std::string>(command, "part", "");
    std::set<std::string> distinct(carried.begin(), carried.end());
    c.require(distinct.size() == carried.size() && !distinct.count(part), "carried: names a body twice, or the gripped part");
    c.require(carried.empty() || !part.empty(), "carried: bodies carried with no part gripped");
    for (const auto& body : gripper_bodies()) {
      c.require(!distinct.count(body), "carried: " + body + " is the arm's own");
    }
  } else if (operation == "translate" || operation == "rotate") {
    c.poses("path", 1);
  } else if (operation == "screw") {
    c.poses("path", 1).text("destination", true).at_least("turns", 0).at_least("pitch", 0);
    const double turns = get_or<double>(command, "turns", 0), pitch = get_or<double>(command, "pitch", 0);
    c.require(turns > 0 && turns <= kMostTurns, "turns: must be above 0 and at most " + std::to_string(int(kMostTurns)));
    c.require(pitch > 0 && pitch <= kMostPitch, "pitch: must be above 0 and at most 0.05 m");
    if (!c.ok()) return;
    // The path turns as far as the command says (each pose's turn from the last, summed).
    const Numbers& path = get<Numbers>(command, "path");
    double turned = 0;
    for (std::size_t i = 7; i + 7 <= path.size(); i += 7) {
      const Eigen::Quaterniond from(numbers_pose({path.begin() + i - 7, path.begin() + i}).linear());
      turned += from.angularDistance(Eigen::Quaterniond(numbers_pose({path.begin() + i, path.begin() + i + 7}).linear()));
    }
    std::ostringstream why;
    why << "path: turns " << turned / (2 * kPi) << " times, not the " << turns << " the command says";
    c.require(std::abs(turned - 2 * kPi * turns) <= 0.05 * 2 * kPi * turns + 0.2, why.str());
  } else if (operation == "connect" || operation == "disconnect") {
    c.text("part", true);
  }
}

void ArmBlock::request(Data data) { emit("SIM", std::move(data)); }

void ArmBlock::grip(const Data& d) {
  error_.clear();
  sim_.act_for("");  // the gripper is the arm's own
  const Eigen::Isometry3d pose = numbers_pose(get<Numbers>(d, "path"));
  const auto boxes = gripper_boxes(settings_.gripper, get_or<double>(d, "opening", 0));
  awaited_ = static_cast<int>(boxes.size() * (has_gripper_ ? 2 : 1));
  if (has_gripper_) {
    for (const auto& body : gripper_bodies()) request(sim_.remove(body));
  }
  for (const auto& box : boxes) {
    const Eigen::Vector3d& h = box.half_extents;
    request(sim_.spawn(resource_id() + "/" + box.name, pose_numbers(pose * box.pose), {h.x(), h.y(), h.z()}, false));
  }
  has_gripper_ = true;
  held_ = get<std::string>(d, "part");
  held_order_ = get_or<std::string>(d, "order_id", "");
  carried_ = split_names(get_or<std::string>(d, "carried", ""));
  // In the gripper from the moment the grip begins: a part half gripped when the arm's
  // process ends is one for inspection, and so is every part it carries.
  if (store() && !held_.empty()) store()->grip(held_order_, held_bodies(), resource_id());
}

std::vector<std::string> ArmBlock::held_bodies() const {
  std::vector<std::string> out{held_};
  out.insert(out.end(), carried_.begin(), carried_.end());
  return out;
}

std::vector<std::string> ArmBlock::gripper_bodies() const {
  std::vector<std::string> out;
  for (const auto& box : gripper_boxes(settings_.gripper, 0)) out.push_back(resource_id() + "/" + box.name);
  return out;
}

std::string ArmBlock::recover() {
  std::string out;
  for (const auto& p : store()->hold_for_inspection(resource_id())) {
    out += (out.empty() ? "" : ", ") + p.part + " (" + p.part_type + ", order " + p.order + ")";
  }
  return out.empty() ? "" : "held for inspection: " + out + " (it was in the gripper)";
}

}  // namespace fb
