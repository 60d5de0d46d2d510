#include "twin/planning/path_planner.hpp"

namespace twin {
namespace {

constexpr double kClearance = 0.010;  // m between the part and the assembly before it moves in

Pose moved(const Pose& pose, const Vec3& by) {
  Pose p = pose;
  p.translation() += by;
  return p;
}

}  // namespace

const std::vector<std::pair<std::string, Vec3>>& LinearPathPlanner::directions() {
  static const std::vector<std::pair<std::string, Vec3>> all = {
      {"down", -Vec3::UnitY()}, {"up", Vec3::UnitY()},  {"+x", Vec3::UnitX()},
      {"-x", -Vec3::UnitX()},   {"+z", Vec3::UnitZ()}, {"-z", -Vec3::UnitZ()}};
  return all;
}

Trajectory LinearPathPlanner::straight_insertion(const AssemblyScene& scene, PartIndex part, const std::string& label,
                                                 const Vec3& direction) {
  const Pose final_pose = scene.product().product.parts()[part].final_pose;
  const Eigen::AlignedBox3d part_box = scene.final_bounds(part);
  Eigen::AlignedBox3d around = scene.assembled_bounds();
  around.extend(part_box);

  int axis = 0;
  direction.cwiseAbs().maxCoeff(&axis);
  const bool positive = direction[axis] > 0;
  // How far back along the direction the part starts: clear of everything assembled.
  const double clear = positive ? part_box.max()[axis] - around.min()[axis] : around.max()[axis] - part_box.min()[axis];
  const double distance = std::max(clear, part_box.sizes()[axis]) + kClearance;
  const Pose pre = moved(final_pose, -direction * distance);
  // Raise the start above everything, so that the part arrives from a safe height.
  const double raise = std::max(0.0, around.max().y() + kClearance - (part_box.min().y() - direction.y() * distance));

  Trajectory t;
  t.direction = direction;
  t.retreat = distance;
  t.label = label;
  auto add = [&](const char* phase, const Pose& part_pose, bool holding) {
    t.waypoints.push_back({phase, part_pose, part_pose, holding});
  };
  if (raise > 1e-9) add("approach", moved(pre, Vec3::UnitY() * raise), true);
  add(raise > 1e-9 ? "transit" : "approach", pre, true);
  add("insert", final_pose, true);
  add("release", final_pose, false);
  add("retreat", final_pose, false);
  const auto grasps = scene.grasps(part, direction);
  t.hold_by(grasps.empty() ? Grasp{} : grasps.front());
  return t;
}

std::optional<Trajectory> LinearPathPlanner::next(const AssemblyScene& scene, PartIndex part,
                                                  const std::vector<Attempt>& tried) {
  if (tried.size() >= directions().size()) return std::nullopt;
  const auto& [label, direction] = directions()[tried.size()];
  return straight_insertion(scene, part, label, direction);
}


}  // namespace twin
