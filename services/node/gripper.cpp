#include "services/node/gripper.hpp"

#include <algorithm>
#include <cmath>

namespace fb {

const std::vector<std::pair<std::string, double GripperGeometry::*>>& gripper_sizes() {
  using G = GripperGeometry;
  static const std::vector<std::pair<std::string, double G::*>> all = {
      {"finger_length", &G::finger_length}, {"finger_thickness", &G::finger_thickness},
      {"finger_width", &G::finger_width},   {"palm_thickness", &G::palm_thickness},
      {"max_opening", &G::max_opening},     {"carriage_width", &G::carriage_width},
      {"carriage_length", &G::carriage_length}};
  return all;
}

std::string gripper_option(const std::string& size_name) {
  std::string flag = "--gripper-" + size_name;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

std::string GripperGeometry::problem() const {
  for (const auto& [name, size] : gripper_sizes()) {
    if (!std::isfinite(this->*size) || this->*size <= 0) return "gripper " + name + " must be a length above 0";
  }
  return "";
}

std::vector<GripperBox> gripper_boxes(const GripperGeometry& g, double opening) {
  const auto at = [](double x, double y) {
    Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
    p.translation() = Eigen::Vector3d(x, y, 0);
    return p;
  };
  const double finger_x = opening / 2 + g.finger_thickness / 2;
  const Eigen::Vector3d finger(g.finger_thickness / 2, g.finger_length / 2, g.finger_width / 2);
  const double palm = g.palm_thickness / 2;
  return {
      {"palm", at(0, 0), Eigen::Vector3d(opening / 2 + g.finger_thickness, palm, g.finger_width / 2)},
      {"finger-1", at(-finger_x, -palm - g.finger_length / 2), finger},
      {"finger-2", at(finger_x, -palm - g.finger_length / 2), finger},
      {"carriage", at(0, palm + g.carriage_length / 2),
       Eigen::Vector3d(g.carriage_width / 2, g.carriage_length / 2, g.carriage_width / 2)},
  };
}

Numbers pose_numbers(const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.linear());
  const Eigen::Vector3d& t = pose.translation();
  return {t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z()};
}

Eigen::Isometry3d numbers_pose(const Numbers& n) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = Eigen::Quaterniond(n[3], n[4], n[5], n[6]).normalized().toRotationMatrix();
  p.translation() = Eigen::Vector3d(n[0], n[1], n[2]);
  return p;
}

}  // namespace fb
