#pragma once
// How long cell-sim takes for one straight segment of a move: the longer of the translation
// at `speed` and the turn at `angular_speed` (0: turning takes no time). cell-sim's clock
// advances so (SimWorld::move), and a twin's quote times the arm's paths with the same rule.

#include <algorithm>

#include <Eigen/Geometry>

namespace sim {

inline double segment_duration(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to, double speed,
                               double angular_speed) {
  const double length = (to.translation() - from.translation()).norm();
  const double angle = Eigen::Quaterniond(from.linear()).angularDistance(Eigen::Quaterniond(to.linear()));
  return std::max(length / speed, angular_speed > 0 ? angle / angular_speed : 0.0);
}

}  // namespace sim
