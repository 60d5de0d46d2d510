#pragma once
// The arm's gripper as bodies: a pad (a box at the grasp) and a carriage behind it, against
// the push, along the push's main axis. The arm spawns them in the physical cell; a twin
// spawns the same bodies in its virtual scene, so that virtual assembly meets what the arm
// will meet.

#include "services/runtime/event.hpp"

namespace fb {

struct GripperSize {
  double carriage_width = 0.020;   // m
  double carriage_length = 0.150;  // m
};

struct Carriage {
  Numbers pose;          // x, y, z, qw, qx, qy, qz
  Numbers half_extents;  // m
};

// `pad_pose`: seven numbers; `pad_half`: the pad's half extents; `push`: the push direction.
Carriage carriage_behind(const Numbers& pad_pose, const Numbers& pad_half, const Numbers& push, const GripperSize& size);

}  // namespace fb
