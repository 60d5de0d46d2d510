#pragma once
// Assembly path planning: the role of the paper's planAssemblyPath. Virtual assembly asks
// for a trajectory, runs it, and on a collision asks again with what it learned.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "twin/planning/assembly_scene.hpp"

namespace twin {

struct Attempt {
  Trajectory trajectory;
  std::optional<Collision> collision;  // empty: it worked
};

class PathPlanner {
 public:
  virtual ~PathPlanner() = default;
  virtual std::string name() const = 0;
  // The next trajectory to try for the part, given this part's earlier tries against the
  // same assembled parts; nothing when the planner has no more.
  virtual std::optional<Trajectory> next(const AssemblyScene& scene, PartIndex part,
                                         const std::vector<Attempt>& tried) = 0;
  // Whether a trajectory with more parts in place holds the insertion, release and retreat of
  // the same one with fewer (the search then takes a collision there as known: KnownCollisions).
  virtual bool trajectories_nest() const { return false; }
};

// Straight insertion along candidate directions: down, up from below, +x, -x, +z, -z. The
// part comes from a safe height to a point clear of the assembly along the direction,
// moves straight in, is released, and the arm backs out along its carriage. The trajectory
// holds the part by its first grasp for the direction; virtual assembly may choose another.
class LinearPathPlanner : public PathPlanner {
 public:
  std::string name() const override { return "linear"; }
  std::optional<Trajectory> next(const AssemblyScene& scene, PartIndex part,
                                 const std::vector<Attempt>& tried) override;
  // It starts farther back, and backs out farther, as the assembly grows, on the same lines.
  bool trajectories_nest() const override { return true; }

  static const std::vector<std::pair<std::string, Vec3>>& directions();
  static Trajectory straight_insertion(const AssemblyScene& scene, PartIndex part, const std::string& label,
                                       const Vec3& direction);
};

std::unique_ptr<PathPlanner> make_path_planner(const std::string& name);

}  // namespace twin
