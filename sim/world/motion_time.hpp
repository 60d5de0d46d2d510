#pragma once
// How long cell-sim takes for one straight segment of a move: the longer of the translation
// at `speed` and the turn at `angular_speed` (0: turning takes no time). cell-sim's clock
// advances so (SimWorld::move), and a twin's quote times the arm's paths with the same rule.

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Geometry>

namespace sim {

inline double segment_duration(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to, double speed,
                               double angular_speed) {
  const double length = (to.translation() - from.translation()).norm();
  const double angle = Eigen::Quaterniond(from.linear()).angularDistance(Eigen::Quaterniond(to.linear()));
  return std::max(length / speed, angular_speed > 0 ? angle / angular_speed : 0.0);
}

// A mobile robot drives on the floor: cell-sim moves it between docks at y 0, so a drive is
// as long as the docks are apart in x and z. Its bids and a twin's quote count it so.
inline double floor_distance(const std::vector<double>& a, const std::vector<double>& b) {
  return std::hypot(a[0] - b[0], a[2] - b[2]);
}

}  // namespace sim
