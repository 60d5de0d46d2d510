#pragma once
// The virtual cell for one product: the station's surface, the parts assembled so far as
// static bodies, and the arm's gripper (palm, fingers, carriage) with the part it holds.
// Virtual assembly runs trajectories here; collisions with parts, station and arm all count.

#include <map>
#include <optional>
#include <set>
#include <tuple>
#include <vector>

#include "sim/collision/collision_world.hpp"
#include "twin/geometry/product_loader.hpp"
#include "twin/planning/trajectory.hpp"

namespace twin {

struct Collision {
  std::string with;     // a part's name or "station"
  std::string member;   // what hit it: "part", "finger", "palm", "carriage"
  double depth = 0;     // m
  std::string phase;    // of the trajectory; "grasp": no grasp fits the part (depth: by how much);
                        // "gripping": a finger of the grasp closes on air
};

// The least room a part had on its way in: how near it, or the gripper holding it, came to
// another body.
struct Margin {
  double distance = 0;  // m
  std::string with;     // a part's name or "station"
  std::string member;   // what came that near: "part", "finger", "palm", "carriage"
  std::string phase;    // of the trajectory
};

// The part in the gripper, as the collision world sees it.
struct HeldPart {
  sim::MovingBody with_arm;  // part + gripper, in the part's frame
  sim::MovingBody arm;       // the gripper, in its own frame
};

class AssemblyScene;

// Collisions that recur: where a grasp's part or gripper hit the station, or a part in place,
// while inserting, releasing or backing out, it hits it again whenever that part is in place,
// for a path planner whose trajectories nest (PathPlanner::trajectories_nest). The search keeps
// them by part, trajectory and grasp, and runs a grasp only where none recurs.
class KnownCollisions {
 public:
  std::optional<Collision> recurring(const AssemblyScene& scene, PartIndex part, const std::string& trajectory,
                                     const std::string& grasp) const;
  void remember(PartIndex part, const std::string& trajectory, const std::string& grasp, const Collision& collision);
  std::size_t answered() const { return answered_; }

 private:
  std::map<std::tuple<PartIndex, std::string, std::string>, std::vector<Collision>> known_;
  mutable std::size_t answered_ = 0;
};

class AssemblyScene {
 public:
  AssemblyScene(const LoadedProduct& product, sim::CollisionOptions options = {}, fb::GripperGeometry gripper = {});

  const LoadedProduct& product() const { return product_; }
  const fb::GripperGeometry& gripper() const { return gripper_; }

  // Joins two parts as a link does (a thread the geometry shows: threads.hpp).
  void link(PartIndex a, PartIndex b);
  void assemble(PartIndex part);
  void disassemble(PartIndex part);
  bool is_assembled(PartIndex part) const { return bodies_.count(part) > 0; }
  std::size_t assembled_count() const { return bodies_.size(); }

  // The part's bounding box in the finished product.
  const Eigen::AlignedBox3d& final_bounds(PartIndex part) const { return bounds_[part]; }
  // The box of what the gripper holds the part by, where its grasps sit (LoadedProduct::held_by).
  const Eigen::AlignedBox3d& grasp_bounds(PartIndex part) const { return grasp_bounds_[part]; }
  // The assembled parts' bounding box (empty when nothing is assembled).
  const Eigen::AlignedBox3d& assembled_bounds() const { return assembled_bounds_; }
  // Unassembled parts the links allow next: standing on the station's surface (which holds
  // them) or linked to an assembled part, and every part the product's precedences put
  // before them in. Kept up to date as parts come and go.
  const std::set<PartIndex>& frontier() const { return frontier_; }
  bool stands_on_surface(PartIndex part) const;

  // The gripper's grasps on the part (on what it holds it by) for a push along `direction`,
  // best first (grasp.hpp).
  std::vector<Grasp> grasps(PartIndex part, const Vec3& direction) const;
  // The part in the gripper, held by `grasp`. Made once per part and grasp: a concave part's
  // exact body (a convex child per triangle, 24 000 for a CAD beam) and its solid cost more to
  // make than the checks that use them.
  const HeldPart& hold(PartIndex part, const Grasp& grasp) const;
  std::optional<Collision> collision_at(const sim::MovingBody& body, const Pose& pose, const std::string& phase) const;

  // Whether the grasp's fingers both have the part's surface at their pads (a finger on a
  // face of a concave part's box may close on air: finger_contact.hpp).
  bool holds(PartIndex part, const Grasp& grasp) const;
  // How many of a subassembly's grasps (by its base) holds() refused so far because the
  // gripper would stand in its other members.
  std::size_t grasps_in_members(PartIndex part) const;
  // Runs the trajectory in the collision world: the held part with the arm, then the arm
  // alone once it has let go. The first collision, or nothing; a grasp that does not hold
  // the part is one of phase "gripping", before any move.
  std::optional<Collision> simulate(PartIndex part, const Trajectory& trajectory) const;
  // Runs the trajectory with its own grasp, then with the part's other grasps for its
  // direction, then with each of them beside the part's centre (off_centre_grasps, grasp.hpp),
  // and keeps the first that is free of collisions through insertion and retreat. Where none
  // is, the trajectory keeps its own grasp and the answer is its collision (or, with no grasp
  // at all, one of phase "grasp"). With `known`, a grasp whose collision recurs is not run
  // again, and what is found is remembered there.
  std::optional<Collision> simulate_grasps(PartIndex part, Trajectory& trajectory, KnownCollisions* known = nullptr) const;

  // The least room the part, and the gripper holding it, have on the trajectory's way in
  // (every stretch it is held), within `reach`: nothing when there is more. This is the room
  // across the motion: where the part closes on a surface head-on, along the insertion
  // direction, it is coming to its seat, meant to close, and that contact is left out.
  std::optional<Margin> margin(PartIndex part, const Trajectory& trajectory, double reach) const;
  // The triangles the part is measured by, one convex shape each, where it is one concave
  // piece; 0 where its mesh is convex pieces.
  std::size_t exact_triangles(PartIndex part) const;

  const sim::CollisionWorld& world() const { return world_; }

 private:
  Collision to_collision(const sim::Contact& contact, const std::string& phase) const;
  // The body of the part a trajectory turns its part into (Trajectory::screw), where it stands;
  // else -1.
  sim::BodyId thread_mate(const Trajectory& trajectory) const;

  const LoadedProduct& product_;
  fb::GripperGeometry gripper_;
  sim::CollisionWorld world_;
  std::vector<PartIndex> neighbours(PartIndex part) const;
  bool linked_to_assembled(PartIndex part) const;
  void update_frontier(PartIndex part);

  // What the gripper holds the part by (LoadedProduct::held_by).
  const std::shared_ptr<const sim::TriangleMesh>& held_by(PartIndex part) const;
  // How what the gripper holds a part by stands turned about the vertical (grasp.hpp), found
  // when its grasps are first asked.
  struct Footprint {
    double yaw = 0;
    bool turned = false;  // more than a degree off the axes
    Eigen::AlignedBox3d turned_box;  // in the world turned back by the yaw
  };
  const Footprint& footprint(PartIndex part) const;
  mutable std::map<PartIndex, Footprint> footprints_;
  // off_centre_grasps() of each grasp, by part and the centred grasp's label: found from the
  // part's triangles, when every centred grasp failed.
  const std::vector<Grasp>& off_centre(PartIndex part, const Grasp& centred) const;
  mutable std::map<std::pair<PartIndex, std::string>, std::vector<Grasp>> off_centre_;

  std::vector<Eigen::AlignedBox3d> bounds_;
  std::vector<Eigen::AlignedBox3d> grasp_bounds_;  // of what the gripper holds each part by
  Eigen::AlignedBox3d assembled_bounds_;
  std::set<PartIndex> frontier_;
  std::vector<std::pair<PartIndex, PartIndex>> links_;  // besides the product's (link())
  std::map<PartIndex, sim::BodyId> bodies_;
  std::map<sim::BodyId, std::string> names_;
  // holds(), by part and grasp label (a label names one grasp of a part's box).
  mutable std::map<std::pair<PartIndex, std::string>, bool> holds_;
  // hold(), by part, grasp label and opening.
  mutable std::map<std::tuple<PartIndex, std::string, double>, HeldPart> held_;
  mutable std::map<PartIndex, std::set<std::string>> in_members_;  // grasps refused: the gripper in other members
};

}  // namespace twin
