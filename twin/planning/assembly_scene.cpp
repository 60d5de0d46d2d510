#include "twin/planning/assembly_scene.hpp"

#include <algorithm>

namespace twin {
namespace {

constexpr double kOnSurface = 1e-4;  // m: a part this close to y = 0 stands on the station

// Index and sign of a direction's dominant axis.
std::pair<int, double> dominant_axis(const Vec3& direction) {
  int axis = 0;
  direction.cwiseAbs().maxCoeff(&axis);
  return {axis, direction[axis] > 0 ? 1.0 : -1.0};
}

Pose translation(const Vec3& t) {
  Pose p = Pose::Identity();
  p.translation() = t;
  return p;
}

}  // namespace

AssemblyScene::AssemblyScene(const LoadedProduct& product, sim::CollisionOptions options, ArmGeometry arm)
    : product_(product), arm_(arm), world_(options) {
  const auto& parts = product.product.parts();
  for (PartIndex i = 0; i < parts.size(); ++i) {
    Eigen::AlignedBox3d box;
    if (const auto& mesh = product.meshes[i]) {
      for (const auto& v : mesh->vertices) box.extend(parts[i].final_pose * v);
    } else {
      box.extend(parts[i].final_pose.translation());
    }
    bounds_.push_back(box);
  }
  for (PartIndex i = 0; i < parts.size(); ++i) update_frontier(i);
  // The station's surface: a slab whose top is the assembly surface, y = 0.
  const sim::BodyId station = world_.add_static_box("station", Vec3(1.0, 0.025, 1.0), translation(Vec3(0, -0.025, 0)));
  names_[station] = "station";
}

void AssemblyScene::assemble(PartIndex part) {
  if (is_assembled(part)) return;
  const auto& p = product_.product.parts()[part];
  const sim::BodyId id = world_.add_static_mesh(p.name, product_.meshes[part], p.final_pose);
  bodies_[part] = id;
  names_[id] = p.name;
  assembled_bounds_.extend(bounds_[part]);
  update_frontier(part);
  for (PartIndex neighbour : neighbours(part)) update_frontier(neighbour);
}

void AssemblyScene::disassemble(PartIndex part) {
  const auto it = bodies_.find(part);
  if (it == bodies_.end()) return;
  world_.remove(it->second);
  names_.erase(it->second);
  bodies_.erase(it);
  assembled_bounds_.setEmpty();
  for (const auto& [p, _] : bodies_) assembled_bounds_.extend(bounds_[p]);
  update_frontier(part);
  for (PartIndex neighbour : neighbours(part)) update_frontier(neighbour);
}

std::vector<PartIndex> AssemblyScene::neighbours(PartIndex part) const {
  std::vector<PartIndex> out;
  const Product& product = product_.product;
  for (std::size_t ci : product.connections_of(part)) {
    const Connection& c = product.connections()[ci];
    out.push_back(c.part1 == part ? c.part2 : c.part1);
  }
  return out;
}

bool AssemblyScene::stands_on_surface(PartIndex part) const { return bounds_[part].min().y() < kOnSurface; }

bool AssemblyScene::linked_to_assembled(PartIndex part) const {
  const auto n = neighbours(part);
  return std::any_of(n.begin(), n.end(), [&](PartIndex q) { return is_assembled(q); });
}

void AssemblyScene::update_frontier(PartIndex part) {
  if (!is_assembled(part) && (stands_on_surface(part) || linked_to_assembled(part))) {
    frontier_.insert(part);
  } else {
    frontier_.erase(part);
  }
}

Eigen::Vector3d AssemblyScene::pad_half_extents(PartIndex part, const Vec3& direction) const {
  const int axis = dominant_axis(direction).first;
  Eigen::Vector3d half = bounds_[part].sizes().cwiseMin(arm_.pad_max_width) / 2;
  half[axis] = arm_.pad_thickness / 2;
  return half;
}

Pose AssemblyScene::grip_offset(PartIndex part, const Vec3& direction) const {
  const auto [axis, sign] = dominant_axis(direction);
  const Eigen::AlignedBox3d& box = bounds_[part];
  Vec3 centre = box.center();
  // The face behind the part: the pad pushes it along `direction`.
  centre[axis] = (sign > 0 ? box.min()[axis] : box.max()[axis]) - sign * arm_.pad_thickness / 2;
  return product_.product.parts()[part].final_pose.inverse() * translation(centre);
}

HeldPart AssemblyScene::hold(PartIndex part, const Vec3& direction) const {
  const auto [axis, sign] = dominant_axis(direction);
  const Eigen::Vector3d pad = pad_half_extents(part, direction);
  Eigen::Vector3d carriage = Eigen::Vector3d::Constant(arm_.carriage_width / 2);
  carriage[axis] = arm_.carriage_length / 2;
  // In the gripper's frame (world-aligned at the final pose): the carriage runs away from
  // the part, behind the pad.
  Vec3 carriage_offset = Vec3::Zero();
  carriage_offset[axis] = -sign * (arm_.pad_thickness / 2 + arm_.carriage_length / 2);

  const double margin = world_.options().shape_margin;
  HeldPart held;
  held.grip = grip_offset(part, direction);
  if (const auto& mesh = product_.meshes[part]) held.with_arm.add_mesh("part", *mesh, Pose::Identity(), margin);
  held.with_arm.add_box("gripper", pad, held.grip, margin);
  held.with_arm.add_box("carriage", carriage, held.grip * translation(carriage_offset), margin);
  held.arm.add_box("gripper", pad, Pose::Identity(), margin);
  held.arm.add_box("carriage", carriage, translation(carriage_offset), margin);
  return held;
}

std::optional<Collision> AssemblyScene::collision_at(const sim::MovingBody& body, const Pose& pose,
                                                     const std::string& phase) const {
  if (auto c = world_.penetration(body, pose)) return to_collision(*c, phase);
  return std::nullopt;
}

std::optional<Collision> AssemblyScene::simulate(PartIndex part, const Trajectory& trajectory) const {
  const auto& w = trajectory.waypoints;
  if (w.empty()) return std::nullopt;
  const HeldPart held = hold(part, trajectory.grip_direction);
  if (w.front().holding) {
    if (auto c = collision_at(held.with_arm, w.front().part, w.front().phase)) return c;
  }
  for (std::size_t i = 1; i < w.size(); ++i) {
    const auto contact = w[i].holding ? world_.sweep(held.with_arm, w[i - 1].part, w[i].part)
                                      : world_.sweep(held.arm, w[i - 1].gripper, w[i].gripper);
    if (contact) return to_collision(*contact, w[i].phase);
  }
  return std::nullopt;
}

Collision AssemblyScene::to_collision(const sim::Contact& contact, const std::string& phase) const {
  const auto it = names_.find(contact.body);
  return {it == names_.end() ? contact.body_name : it->second, contact.member, contact.depth, phase};
}

}  // namespace twin
