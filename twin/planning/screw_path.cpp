#include "twin/planning/screw_path.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "twin/planning/path_planner.hpp"

namespace twin {
namespace {

constexpr double kClearance = 0.010;         // m between the part and the mate's thread before it turns
constexpr double kStep = EIGEN_PI / 18;           // rad between the helix's waypoints: 10 degrees
constexpr double kWaypointsAtMost = 1800;    // 50 turns; a longer thread is not planned

// The pose turned by `angle` about the line through `point` along `axis`.
Pose turned(const Pose& pose, const Vec3& point, const Vec3& axis, double angle) {
  Pose about = Pose::Identity();
  about.translate(point);
  about.rotate(Eigen::AngleAxisd(angle, axis));
  about.translate(-point);
  return about * pose;
}

// Along `back`, from the thread's middle: the farthest the mate's thread reaches and the
// nearest the part's does (their surfaces within a pitch of the thread's radius).
double clear_after(const LoadedProduct& product, PartIndex part, const Thread& thread, const Vec3& back) {
  const auto extent = [&](PartIndex p, bool farthest) {
    double out = farthest ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
    const Pose& pose = product.product.parts()[p].final_pose;
    for (const Vec3& v : product.meshes[p]->vertices) {
      const Vec3 d = pose * v - thread.centre;
      const double along = d.dot(thread.axis);
      if (std::abs((d - along * thread.axis).norm() - thread.diameter / 2) > thread.pitch) continue;
      const double t = d.dot(back);
      out = farthest ? std::max(out, t) : std::min(out, t);
    }
    return out;
  };
  return extent(thread.other(part), true) - extent(part, false);
}

}  // namespace

std::vector<Trajectory> screw_insertions(const AssemblyScene& scene, PartIndex part, const Thread& thread) {
  std::vector<Trajectory> out;
  const LoadedProduct& product = scene.product();
  if (!product.meshes[part] || !product.meshes[thread.other(part)] || thread.pitch <= 0) return out;
  const Pose final_pose = product.product.parts()[part].final_pose;
  for (const double sense : {1.0, -1.0}) {
    const Vec3 direction = thread.axis * sense;
    const double travel = std::max(clear_after(product, part, thread, -direction), thread.length) + thread.pitch;
    const double angle = 2 * EIGEN_PI * travel / thread.pitch;
    if (angle / kStep > kWaypointsAtMost) continue;
    // Where the helix begins: backed off along the axis and turned back.
    const auto on_helix = [&](double u) {  // u: 0 at the start, 1 in place
      Pose p = turned(final_pose, thread.centre, direction, -(1 - u) * angle);
      p.translation() -= direction * ((1 - u) * travel);
      return p;
    };
    // The straight way in to the helix's start, from the linear planner's insertion along the
    // axis: its poses before the insertion, turned as the helix starts and backed off past it.
    std::string label;
    for (const auto& [name, d] : LinearPathPlanner::directions()) {
      if (d.dot(direction) > 1 - 1e-9) label = name;
    }
    Trajectory straight = LinearPathPlanner::straight_insertion(scene, part, label.empty() ? "axis" : label, direction);
    const double further = std::max(0.0, travel + kClearance - straight.retreat);
    Trajectory t;
    t.direction = direction;
    t.label = "screw " + straight.label;
    t.retreat = std::max(straight.retreat, kClearance);
    for (const Waypoint& w : straight.waypoints) {
      if (w.phase == "insert") break;
      Pose p = turned(w.part, thread.centre, direction, -angle);
      p.translation() -= direction * further;
      t.waypoints.push_back({w.phase, p, p, true});
    }
    t.waypoints.push_back({"insert", on_helix(0), on_helix(0), true});
    const int steps = static_cast<int>(std::ceil(angle / kStep));
    for (int k = 1; k <= steps; ++k) {
      const Pose p = on_helix(static_cast<double>(k) / steps);
      t.waypoints.push_back({"screw", p, p, true});
    }
    t.waypoints.push_back({"release", final_pose, final_pose, false});
    t.waypoints.push_back({"retreat", final_pose, final_pose, false});
    t.screw = Screw{thread.other(part), direction, thread.centre, thread.pitch, travel / thread.pitch, thread.depth};
    const auto grasps = scene.grasps(part, direction);
    t.hold_by(grasps.empty() ? Grasp{} : grasps.front());
    out.push_back(std::move(t));
  }
  return out;
}

}  // namespace twin
