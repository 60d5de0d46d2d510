#pragma once
// The collision world: static bodies (assembled parts, concave: a compound of the mesh's
// convex pieces, or a triangle-mesh BVH for a one-piece mesh, so that a peg can pass
// through a hole; the station's surface as a box) and moving bodies (the gripped part and
// the gripper and carriage: convex pieces where the mesh is authored so, and for a
// one-piece mesh its hull first and, where the hull penetrates, its exact triangles).
// Touching is not colliding: only penetration deeper than the contact tolerance counts.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "sim/mesh/triangle_mesh.hpp"

namespace sim {

using Pose = Eigen::Isometry3d;
using BodyId = int;

struct CollisionOptions {
  double contact_tolerance = 3e-4;  // m: deeper penetration than this is a collision
  double linear_step = 1e-3;        // m: largest move of any point between swept samples
  double shape_margin = 5e-5;       // m: Bullet's collision margin on every shape
};

struct Contact {
  BodyId body = -1;         // the static body hit
  std::string body_name;
  std::string member;       // which member of the moving body: "part", "gripper", ...
  double depth = 0;         // m, positive
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double fraction = 0;      // where along a sweep, 0..1
};

// How near the moving body comes to a static body: the distance between their surfaces, as
// the collision world holds them (to within the shapes' margins).
struct Clearance {
  BodyId body = -1;
  std::string body_name;
  std::string member;  // of the moving body
  double distance = 0;  // m; 0 where they touch or overlap
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, from the static body towards the moving one
};
// Which pairs count: false leaves a pair out (a contact that is meant to be).
using ClearanceFilter = std::function<bool(const Clearance&)>;

class CollisionWorld;

// The pose a fraction s (0..1) of the way: translation linear, rotation slerp.
Pose interpolate(const Pose& from, const Pose& to, double s);

// Something that moves: named members, each a convex decomposition at an offset.
class MovingBody {
 public:
  MovingBody();
  ~MovingBody();
  MovingBody(MovingBody&&) noexcept;
  MovingBody& operator=(MovingBody&&) noexcept;

  // Each piece of a mesh authored as pieces becomes one convex hull, and so does a convex
  // mesh; a concave one-piece mesh is checked by its hull and then, near contact, by its
  // triangles. Triangles are a surface: two faces that overlap flat, where no triangles
  // cross, go unseen (the finished product's interference check, which is volumetric,
  // catches those at the final poses). Where its triangles touch or cross a concave static
  // part's, points of each in the other's volume tell the depth (sim/mesh/solid.hpp).
  void add_mesh(const std::string& member, std::shared_ptr<const TriangleMesh> mesh, const Pose& offset, double margin);
  void add_mesh(const std::string& member, const TriangleMesh& mesh, const Pose& offset, double margin);  // a copy
  void add_box(const std::string& member, const Eigen::Vector3d& half_extents, const Pose& offset, double margin);
  // Largest distance of any point from the body's origin: bounds how far points move when
  // it turns.
  double radius() const { return radius_; }
  bool empty() const;

 private:
  friend class CollisionWorld;
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double radius_ = 0;
};

// Static bodies and the checks of moving bodies against them. One thread at a time: the const
// checks fill caches (volumes, exact shapes) in the world and in the moving body.
class CollisionWorld {
 public:
  explicit CollisionWorld(CollisionOptions options = {});
  ~CollisionWorld();
  CollisionWorld(const CollisionWorld&) = delete;
  CollisionWorld& operator=(const CollisionWorld&) = delete;

  const CollisionOptions& options() const { return options_; }

  // A concave static body; bodies of one mesh share one shape.
  BodyId add_static_mesh(const std::string& name, std::shared_ptr<const TriangleMesh> mesh, const Pose& pose);
  BodyId add_static_box(const std::string& name, const Eigen::Vector3d& half_extents, const Pose& pose);
  void remove(BodyId body);

  // A penetration of the body at a pose deeper than the tolerance, if there is one: the deepest
  // where pieces meet as convex shapes; where a concave member goes into a concave body, the
  // first point found past the tolerance, whose depth is then a least one.
  // `ignore`: a body the moving one may go into (a nut on the bolt it turns onto).
  std::optional<Contact> penetration(const MovingBody& body, const Pose& pose, BodyId ignore = -1) const;
  // The first collision while moving from one pose to another, translating and turning
  // together (slerp), sampled so that no point moves more than linear_step between samples.
  std::optional<Contact> sweep(const MovingBody& body, const Pose& from, const Pose& to, BodyId ignore = -1) const;
  // The nearest static body within `reach` of the moving body at the pose, of the pairs that
  // `counts` (when given) keeps; nothing when none is that near.
  std::optional<Clearance> nearest(const MovingBody& body, const Pose& pose, double reach,
                                   const ClearanceFilter& counts = {}) const;
  // The same along a move: exact for a move without turning (each piece's swept volume);
  // with turning, sampled so that no point moves more than linear_step between samples.
  // Stretches farther than `reach` from every body are skipped whole. `closing`: the member
  // that the move brings to its seat; where the move does not turn, what lies wholly beyond
  // where its pieces end up, along the move, is left out (it never comes beside them).
  std::optional<Clearance> nearest_along(const MovingBody& body, const Pose& from, const Pose& to, double reach,
                                         const ClearanceFilter& counts = {}, const std::string& closing = "") const;
  // Penetration tests made so far (for benchmarks).
  std::size_t checks() const { return checks_; }

 private:
  bool clear_translation(const MovingBody& body, const Pose& from, const Eigen::Vector3d& shift) const;
  std::optional<Clearance> nearest_translating(const MovingBody& body, const Pose& from, const Eigen::Vector3d& shift,
                                               double reach, const ClearanceFilter& counts,
                                               const std::string& closing) const;

  struct Impl;
  std::unique_ptr<Impl> impl_;
  CollisionOptions options_;
  mutable std::size_t checks_ = 0;
};

}  // namespace sim
