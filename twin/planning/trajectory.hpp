#pragma once
// What the arm does to assemble one part: waypoints of the gripped part and the gripper.

#include <string>
#include <vector>

#include "twin/model/frame.hpp"

namespace twin {

struct Waypoint {
  std::string phase;   // "approach", "transit", "insert", "release", "retreat"
  Pose part;           // the part's pose
  Pose gripper;        // the gripper's pose (its frame: origin at the pad's centre)
  bool holding = true; // the gripper holds the part on the way *to* this waypoint
};

struct Trajectory {
  std::vector<Waypoint> waypoints;
  Vec3 direction = Vec3::Zero();       // unit vector of the final insertion motion
  Vec3 grip_direction = Vec3::Zero();  // the pad sits on the part's face behind this push
  std::string label;              // e.g. "down", "-x", "ompl"

  // Distance the part travels, m.
  double path_length() const;
};

}  // namespace twin
