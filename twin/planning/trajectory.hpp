#pragma once
// What the arm does to assemble one part: waypoints of the gripped part and the gripper.

#include <string>
#include <vector>

#include "twin/planning/grasp.hpp"

namespace twin {

struct Waypoint {
  std::string phase;   // "approach", "transit", "insert", "release", "retreat"
  Pose part;           // the part's pose
  Pose gripper;        // the gripper's pose (its frame: services/node/gripper.hpp)
  bool holding = true; // the gripper holds the part on the way *to* this waypoint
};

struct Trajectory {
  std::vector<Waypoint> waypoints;
  Vec3 direction = Vec3::Zero();       // unit vector of the final insertion motion
  Grasp grasp;                         // how the gripper holds the part
  double retreat = 0.05;               // m the gripper backs away after release, along its carriage
  std::string label;              // e.g. "down", "-x", "ompl"

  // Distance the part travels, m.
  double path_length() const;
  // Holds the part by `grasp`: the gripper follows the part up to the release, then backs
  // away along its carriage, off the part.
  void hold_by(const Grasp& grasp);
};

}  // namespace twin
