#pragma once
// The arm's two-finger parallel gripper as boxes, in the gripper's frame: the fingers close
// along X, they reach down along -Y from the palm, the carriage runs up along +Y from the
// palm's top. The origin is the palm's centre: the palm leads every motion, so a path of
// gripper poses is the palm's path. The arm spawns these boxes
// in the physical cell, a twin spawns them in its virtual scene and its planner puts them in
// its collision world, so that virtual assembly meets what the arm will meet. The palm is as
// wide as the fingers stand apart (the fingers' bridge), not the housing of a real gripper.

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "services/runtime/event.hpp"

namespace fb {

struct GripperGeometry {
  double finger_length = 0.030;     // m, below the palm
  double finger_thickness = 0.006;  // m, along the closing axis
  double finger_width = 0.008;      // m, across it
  double palm_thickness = 0.010;    // m
  double max_opening = 0.200;       // m between the fingers, fully open
  double carriage_width = 0.020;    // m, square section
  double carriage_length = 0.150;   // m, above the palm

  // "" when every size is finite and above 0, else what is wrong.
  std::string problem() const;
};

// Its sizes by name, as the deployment file's `gripper:` spells them (the command lines
// take them as --gripper-<name with dashes>).
const std::vector<std::pair<std::string, double GripperGeometry::*>>& gripper_sizes();
// "finger_length" -> "--gripper-finger-length": the option a process takes it by.
std::string gripper_option(const std::string& size_name);

struct GripperBox {
  std::string name;          // "finger-1", "finger-2", "palm", "carriage"
  Eigen::Isometry3d pose;    // in the gripper's frame
  Eigen::Vector3d half_extents;
};

// The gripper with its fingers `opening` apart. The palm comes first, at the origin.
std::vector<GripperBox> gripper_boxes(const GripperGeometry& gripper, double opening);

// Seven numbers (x, y, z, qw, qx, qy, qz) <-> a pose.
Numbers pose_numbers(const Eigen::Isometry3d& pose);
Eigen::Isometry3d numbers_pose(const Numbers& seven);

}  // namespace fb
