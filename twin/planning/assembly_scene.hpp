#pragma once
// The virtual cell for one product: the station's surface, the parts assembled so far as
// static bodies, and the arm (gripper pad and carriage) with the part it holds. Virtual
// assembly runs trajectories here; collisions with parts, station and arm all count.

#include <map>
#include <optional>
#include <set>
#include <vector>

#include "sim/collision/collision_world.hpp"
#include "twin/geometry/product_loader.hpp"
#include "twin/planning/trajectory.hpp"

namespace twin {

struct ArmGeometry {
  double pad_thickness = 0.010;   // m, along the push direction
  double pad_max_width = 0.030;   // m, the pad is at most this wide, at most the part's face
  double carriage_width = 0.020;  // m, square section
  double carriage_length = 0.150; // m, from the pad away from the part
};

struct Collision {
  std::string with;     // a part's name or "station"
  std::string member;   // what hit it: "part", "gripper", "carriage"
  double depth = 0;     // m
  std::string phase;    // of the trajectory
};

// The part in the gripper, as the collision world sees it.
struct HeldPart {
  sim::MovingBody with_arm;  // part + gripper pad + carriage, in the part's frame
  sim::MovingBody arm;       // gripper pad + carriage, in the gripper's frame
  Pose grip = Pose::Identity();  // the gripper's frame in the part's frame
};

class AssemblyScene {
 public:
  AssemblyScene(const LoadedProduct& product, sim::CollisionOptions options = {}, ArmGeometry arm = {});

  const LoadedProduct& product() const { return product_; }
  const ArmGeometry& arm() const { return arm_; }

  void assemble(PartIndex part);
  void disassemble(PartIndex part);
  bool is_assembled(PartIndex part) const { return bodies_.count(part) > 0; }
  std::size_t assembled_count() const { return bodies_.size(); }

  // The part's bounding box in the finished product.
  const Eigen::AlignedBox3d& final_bounds(PartIndex part) const { return bounds_[part]; }
  // The assembled parts' bounding box (empty when nothing is assembled).
  const Eigen::AlignedBox3d& assembled_bounds() const { return assembled_bounds_; }
  // Unassembled parts the links allow next: standing on the station's surface (which holds
  // them) or linked to an assembled part. Kept up to date as parts come and go.
  const std::set<PartIndex>& frontier() const { return frontier_; }
  bool stands_on_surface(PartIndex part) const;

  // Where the gripper pad sits on the part for a push along `direction`: on the face behind
  // it, in the part's frame.
  Pose grip_offset(PartIndex part, const Vec3& direction) const;

  // The part held for a push along `direction`: the pad on the face behind it, the carriage
  // running away from the part.
  HeldPart hold(PartIndex part, const Vec3& direction) const;
  // Half extents of the gripper pad for that push: as wide as the part's face, at most
  // pad_max_width, pad_thickness along the push.
  Eigen::Vector3d pad_half_extents(PartIndex part, const Vec3& direction) const;
  std::optional<Collision> collision_at(const sim::MovingBody& body, const Pose& pose, const std::string& phase) const;

  // Runs the trajectory in the collision world: the held part with the arm, then the arm
  // alone once it has let go. The first collision, or nothing.
  std::optional<Collision> simulate(PartIndex part, const Trajectory& trajectory) const;

  const sim::CollisionWorld& world() const { return world_; }

 private:
  Collision to_collision(const sim::Contact& contact, const std::string& phase) const;

  const LoadedProduct& product_;
  ArmGeometry arm_;
  sim::CollisionWorld world_;
  std::vector<PartIndex> neighbours(PartIndex part) const;
  bool linked_to_assembled(PartIndex part) const;
  void update_frontier(PartIndex part);

  std::vector<Eigen::AlignedBox3d> bounds_;
  Eigen::AlignedBox3d assembled_bounds_;
  std::set<PartIndex> frontier_;
  std::map<PartIndex, sim::BodyId> bodies_;
  std::map<sim::BodyId, std::string> names_;
};

}  // namespace twin
