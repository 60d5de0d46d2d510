#pragma once
// Sampling-based assembly paths: OMPL's RRT-Connect in SE(3), with the collision world (part,
// gripper and carriage against the assembly and the station) as its validity checker. It
// first offers the straight insertions of LinearPathPlanner and samples only when none works.

#include "twin/planning/path_planner.hpp"

namespace twin {

struct OmplOptions {
  // Each sampling run (one per gripper face) ends after this many collision checks: effort,
  // not seconds, so that a busy machine plans as far as an idle one (a 0.5 s budget failed
  // on a loaded machine). `seconds` is only the safety cap.
  std::size_t max_checks = 100000;
  double seconds = 30;
  double workspace_margin = 0.05; // m around the assembly that the part may use
  double retreat = 0.05;          // m the gripper backs away after release
  unsigned seed = 42;
  double near_orientation_fraction = 0.9;  // samples turned only a little from the final orientation
  double orientation_sigma = 0.15;         // rad, how little
};

class OmplPathPlanner : public PathPlanner {
 public:
  explicit OmplPathPlanner(OmplOptions options = {});
  std::string name() const override { return "ompl"; }
  std::optional<Trajectory> next(const AssemblyScene& scene, PartIndex part,
                                 const std::vector<Attempt>& tried) override;

 private:
  std::optional<Trajectory> sample_path(const AssemblyScene& scene, PartIndex part, const Grasp& grasp) const;

  OmplOptions options_;
  LinearPathPlanner linear_;
};

}  // namespace twin
