#pragma once
// What the arm does to assemble one part: waypoints of the gripped part and the gripper.

#include <optional>
#include <string>
#include <vector>

#include "twin/planning/grasp.hpp"

namespace twin {

struct Waypoint {
  std::string phase;   // "approach", "transit", "insert", "screw", "release", "retreat"
  Pose part;           // the part's pose
  Pose gripper;        // the gripper's pose (its frame: services/node/gripper.hpp)
  bool holding = true; // the gripper holds the part on the way *to* this waypoint
};

// The part turned into its thread (threads.hpp) over the trajectory's "screw" waypoints: about
// `axis` through `point` (product frame), advancing `pitch` per turn along the trajectory's
// direction. Over them the part may go into `mate` by the thread's overlap.
struct Screw {
  std::size_t mate = 0;    // the part it turns into (PartIndex)
  Vec3 axis = Vec3::UnitY();
  Vec3 point = Vec3::Zero();
  double pitch = 0;        // m per turn
  double turns = 0;
  double overlap = 0;      // m: the thread's depth into the mate
};

struct Trajectory {
  std::vector<Waypoint> waypoints;
  Vec3 direction = Vec3::Zero();       // unit vector of the final insertion motion
  Grasp grasp;                         // how the gripper holds the part
  double retreat = 0.05;               // m the gripper backs away after release, along its carriage
  std::string label;              // e.g. "down", "-x", "ompl", "screw down"
  std::optional<Screw> screw;     // where the part is turned into a thread

  // Distance the part travels, m.
  double path_length() const;
  // Holds the part by `grasp`: the gripper follows the part up to the release, then backs
  // away along its carriage, off the part.
  void hold_by(const Grasp& grasp);
};

}  // namespace twin
