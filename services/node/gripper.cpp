#include "services/node/gripper.hpp"

#include <Eigen/Geometry>

namespace fb {

Carriage carriage_behind(const Numbers& pose, const Numbers& pad_half, const Numbers& push, const GripperSize& size) {
  int axis = 0;
  Eigen::Vector3d(push[0], push[1], push[2]).cwiseAbs().maxCoeff(&axis);
  const double sign = push[axis] > 0 ? 1.0 : -1.0;
  Carriage c{pose, Numbers(3, size.carriage_width / 2)};
  c.half_extents[axis] = size.carriage_length / 2;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  offset[axis] = -sign * (pad_half[axis] + size.carriage_length / 2);
  // The offset is in the pad's frame: turn it by the pad's orientation.
  offset = Eigen::Quaterniond(pose[3], pose[4], pose[5], pose[6]).normalized() * offset;
  for (int i = 0; i < 3; ++i) c.pose[i] += offset[i];
  return c;
}

}  // namespace fb
