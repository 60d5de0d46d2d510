#pragma once
// Positions and orientations. Lengths are metres, the product frame is Y-up.

#include <Eigen/Geometry>

namespace twin {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;
using Pose = Eigen::Isometry3d;

// A mechanical interface in its part's own frame. Only the position takes part in
// placement (connection points coincide); the rotation is kept for planners.
struct Frame {
  Vec3 position = Vec3::Zero();
  Quat rotation = Quat::Identity();
};

// AutomationML Frame angles: degrees about the fixed X, then Y, then Z axes,
// i.e. R = Rz(rz) * Ry(ry) * Rx(rx).
Quat rotation_from_xyz_degrees(const Vec3& degrees);

}  // namespace twin
