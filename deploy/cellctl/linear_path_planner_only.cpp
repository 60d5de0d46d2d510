// cellctl's make_path_planner: the linear planner only, so that the process does not load
// OMPL. `cellctl plan --path ompl` runs in cellctl-cell (front_main.cpp), which links
// twin_path_planners (twin/planning/path_planner_factory.cpp) instead of this file.

#include <stdexcept>

#include "twin/planning/path_planner.hpp"

namespace twin {

std::unique_ptr<PathPlanner> make_path_planner(const std::string& name) {
  if (name == "linear") return std::make_unique<LinearPathPlanner>();
  throw std::invalid_argument("the path planner '" + name + "' is not in this process (cellctl-cell has ompl)");
}

}  // namespace twin
