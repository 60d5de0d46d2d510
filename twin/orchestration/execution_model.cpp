#include "twin/orchestration/execution_model.hpp"

#include <stdexcept>

#include "services/node/gripper.hpp"
#include "sim/world/motion_time.hpp"

namespace twin {
namespace {

using fb::Data;
using fb::get;
using fb::Numbers;

const Numbers& dock_of(const ResourceModels& models, const std::string& id) {
  const auto it = models.docks.find(id);
  if (it == models.docks.end() || it->second.size() < 3) throw std::invalid_argument("no dock known for '" + id + "'");
  return it->second;
}

// The arm's gripper along a motion's path from where it is: cell-sim's time for each segment.
double arm_motion(const Data& command, const ResourceModels& models, Pose& gripper) {
  const Numbers& path = get<Numbers>(command, "path");
  double s = 0;
  for (std::size_t i = 0; i + 7 <= path.size(); i += 7) {
    const Pose next = fb::numbers_pose(Numbers(path.begin() + i, path.begin() + i + 7));
    s += sim::segment_duration(gripper, next, models.arm_speed, models.arm_angular_speed);
    gripper = next;
  }
  return s;
}

}  // namespace

ModelledRun run_script(const Script& script, const ResourceModels& models, double station_free, double robot_free) {
  ModelledRun run;
  const double request = models.messages.request * models.real_time_factor;
  const double command = models.messages.command * models.real_time_factor;
  const double fetch = models.messages.fetch * models.real_time_factor;
  run.start = std::max(0.0, station_free);
  double now = run.start;  // the orchestrator's: it runs the actions one after another
  double robot_ready = std::max(run.start, robot_free);
  Numbers robot_at = models.robot_at;
  std::map<std::string, double> delivered;  // fetch command id -> when its part is at the dock
  Pose gripper = Pose::Identity();
  for (const ScriptAction& a : script) {
    switch (a.kind) {
      case ScriptAction::sim:
        now += request;
        break;
      case ScriptAction::send_heard: {  // a fetch: heard, then the robot's when it is free
        now += command / 2;
        const Numbers& source = dock_of(models, get<std::string>(a.data, "source"));
        const Numbers& destination = dock_of(models, get<std::string>(a.data, "destination"));
        const double drive =
            (sim::floor_distance(robot_at, source) + sim::floor_distance(source, destination)) / models.robot_speed;
        robot_ready = std::max(robot_ready, now) + drive + fetch;
        run.robot_s += drive;
        robot_at = destination;
        delivered[get<std::string>(a.data, "command_id")] = robot_ready;
        run.delivered.push_back(robot_ready);
        break;
      }
      case ScriptAction::await_delivery: {
        const auto it = delivered.find(get<std::string>(a.data, "command_id"));
        if (it != delivered.end()) now = std::max(now, it->second);  // else at the dock already
        break;
      }
      case ScriptAction::command: {
        const std::string& operation = get<std::string>(a.data, "operation");
        now += command;
        if (operation == "grip") {
          gripper = fb::numbers_pose(get<Numbers>(a.data, "path"));
        } else if (operation == "translate" || operation == "rotate" || operation == "screw") {
          now += arm_motion(a.data, models, gripper);
        }
        break;
      }
    }
  }
  run.end = now;
  return run;
}

}  // namespace twin
