#include "twin/planning/trajectory.hpp"

namespace twin {

double Trajectory::path_length() const {
  double length = 0;
  for (std::size_t i = 1; i < waypoints.size(); ++i) {
    length += (waypoints[i].part.translation() - waypoints[i - 1].part.translation()).norm();
  }
  return length;
}

}  // namespace twin
