#include <stdexcept>

#include "twin/planning/ompl_path_planner.hpp"

namespace twin {

std::unique_ptr<PathPlanner> make_path_planner(const std::string& name) {
  if (name == "linear") return std::make_unique<LinearPathPlanner>();
  if (name == "ompl") return std::make_unique<OmplPathPlanner>();
  throw std::invalid_argument("unknown path planner '" + name + "' (linear, ompl)");
}

}  // namespace twin
