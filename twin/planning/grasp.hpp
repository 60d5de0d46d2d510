#pragma once
// How the arm's two-finger parallel gripper holds a part: its fingers on a pair of opposite
// faces of the part's box (across a cylinder, its diameter), the carriage on one side. A part
// pushed along a direction has up to thirty grasps; the planner takes the first one that is
// free of collisions through insertion and retreat.

#include <string>
#include <vector>

#include "services/node/gripper.hpp"
#include "sim/mesh/triangle_mesh.hpp"
#include "twin/model/frame.hpp"

namespace twin {

struct Grasp {
  // How far the fingers reach into the part (grasps_for): half-way, a quarter, or as deep as they can.
  enum class Reach { half, shallow, deep };
  Pose gripper = Pose::Identity();  // the gripper's frame (services/node/gripper.hpp) in the part's frame
  double opening = 0;               // m between the fingers: the part's width across them
  std::string label;                // e.g. "across x from above": the closing axis, the carriage's side
  Reach reach = Reach::half;
};

// The grasps on a part whose box in the finished product is `box` (world axes; the part's
// final pose is `final_pose`), for a push along `direction`, best first: the carriage behind
// the push, then above, then beside; never ahead of it. For each side, the narrower pair of
// faces first; a pair wider than the gripper opens is left out. The fingers reach half-way
// into the part, and in a "shallow" grasp after it a quarter of the way, so that they stay
// out of the bore the part goes into; in a "deep" one last as far as they are long, to 2 mm
// short of the part's far side (the low walls of a tray).
std::vector<Grasp> grasps_for(const Eigen::AlignedBox3d& box, const Pose& final_pose, const Vec3& direction,
                              const fb::GripperGeometry& gripper);

// The grasp moved along the fingers' width (across the closing axis and the approach) to a
// quarter of the part's length from either end: for a part whose middle is taken where the
// centred fingers go (a leg stands on a base's centre). The fingers close on the part where
// they then stand: the opening and its centre come from `part`'s surface between them
// (finger_contact.hpp); a position with no surface there, or one wider than the gripper
// opens, is left out, as is every one on a part shorter than four fingers' widths.
std::vector<Grasp> off_centre_grasps(const Grasp& centred, const sim::TriangleMesh& part,
                                     const fb::GripperGeometry& gripper);

// The turn about the vertical (y) that lines a part's footprint up with the axes: the angle in
// [0, pi/2) of the smallest rectangle around the points' (x, z), which lies along an edge of
// their convex hull. A part that stands turned (a stool's leg at 30 degrees) is held across its
// own faces in the frame turned so, where the grasps on its box in the world's axes close on
// its corners.
double footprint_yaw(const std::vector<Vec3>& points);

// The rotation that takes the world to the world turned by -yaw about y, where a footprint at
// `yaw` lies along the axes.
Pose unturn_by(double yaw);

// grasps_for on `turned_box`, the part's box in the world turned by unturn_by(yaw), the
// gripper turned with it; each label says the turn ("across x from above, turned 30 deg").
std::vector<Grasp> turned_grasps_for(const Eigen::AlignedBox3d& turned_box, double yaw, const Pose& final_pose,
                                     const Vec3& direction, const fb::GripperGeometry& gripper);

}  // namespace twin
