#include "twin/planning/trajectory.hpp"

namespace twin {

double Trajectory::path_length() const {
  double length = 0;
  for (std::size_t i = 1; i < waypoints.size(); ++i) {
    length += (waypoints[i].part.translation() - waypoints[i - 1].part.translation()).norm();
  }
  return length;
}

void Trajectory::hold_by(const Grasp& g) {
  grasp = g;
  Pose back = Pose::Identity();
  back.translation() = Vec3(0, retreat, 0);
  for (Waypoint& w : waypoints) w.gripper = w.part * g.gripper * (w.phase == "retreat" ? back : Pose::Identity());
}

}  // namespace twin
