#include "twin/planning/interference.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>

#include "sim/mesh/solid.hpp"

namespace twin {
namespace {

using sim::Solid;
using Point = sim::SolidPoint;

// How deep a's surface reaches into b, each at its pose: the largest distance from b's
// surface of a sample of a's that lies inside b. Only samples farther than the tolerance
// (and than the deepest so far) from b's surface are asked whether they are inside.
// `common`: where the two parts' boxes overlap, in the product's frame. Every sample deeper
// than the tolerance goes into `inside` (product frame).
double depth_into(const Solid& a, const Pose& a_pose, const Solid& b, const Pose& b_pose,
                  const Eigen::AlignedBox3d& common, double tolerance, std::vector<Vec3>& inside) {
  if (!b.inside) return 0;
  const Pose to_b = b_pose.inverse();
  double deepest = 0;
  Point hint = b.mesh.point(*b.mesh.vertices().begin());
  for (const Vec3& sample : a.samples) {
    const Vec3 in_product = a_pose * sample;
    if (!common.contains(in_product)) continue;
    const Vec3 p = to_b * in_product;
    // Samples come a triangle at a time: the last nearest point is a good hint.
    hint = b.surface->closest_point(sim::solid_point(p), hint);
    const double distance = std::sqrt(CGAL::squared_distance(sim::solid_point(p), hint));
    if (distance <= tolerance || !b.contains(sim::solid_point(p))) continue;
    deepest = std::max(deepest, distance);
    inside.push_back(in_product);
  }
  return deepest;
}

}  // namespace

InterferenceCheck find_interferences(const LoadedProduct& product, const sim::CollisionOptions& options) {
  const double tolerance = options.contact_tolerance;
  const auto& parts = product.product.parts();
  std::vector<Eigen::AlignedBox3d> boxes(parts.size());
  for (PartIndex i = 0; i < parts.size(); ++i) {
    if (!product.meshes[i]) continue;
    const auto& b = product.meshes[i]->bounds;
    for (int corner = 0; corner < 8; ++corner) boxes[i].extend(parts[i].final_pose * b.corner(Eigen::AlignedBox3d::CornerType(corner)));
  }
  // Solids only for meshes of parts whose boxes overlap another's by more than the
  // tolerance: parts that merely touch (a brick on a brick) cost nothing.
  std::map<const sim::TriangleMesh*, std::unique_ptr<Solid>> solids;
  const auto solid = [&](PartIndex i) -> const Solid& {
    auto& s = solids[product.meshes[i].get()];
    if (!s) s = sim::solid_of(*product.meshes[i], true);
    return *s;
  };
  // A convex part (or one authored as convex pieces) is a volume to Bullet: when its hull
  // reaches no deeper than the tolerance into the other part and does not lie wholly inside
  // it, the two do not overlap, and the sampled check is spared (a peg in its hole). One
  // world serves every pair: setting up a world costs more than a check.
  std::optional<sim::CollisionWorld> world;
  std::map<PartIndex, sim::MovingBody> moving_bodies;
  const auto is_volume = [](const sim::TriangleMesh& mesh) { return mesh.convex || mesh.pieces.size() > 1; };
  const auto clear_to_bullet = [&](PartIndex moving, PartIndex fixed) {
    const sim::TriangleMesh& mesh = *product.meshes[moving];
    if (!is_volume(mesh)) return false;
    auto [body, fresh] = moving_bodies.try_emplace(moving);
    if (fresh) body->second.add_mesh("part", product.meshes[moving], Pose::Identity(), options.shape_margin);
    if (!world) world.emplace(options);
    const sim::BodyId other_body = world->add_static_mesh(parts[fixed].name, product.meshes[fixed], parts[fixed].final_pose);
    const bool hit = world->penetration(body->second, parts[moving].final_pose).has_value();
    world->remove(other_body);
    if (hit) return false;
    // Wholly inside a volume is a deep hit; inside a triangle surface is no contact at all.
    if (is_volume(*product.meshes[fixed])) return true;
    const Solid& other = solid(fixed);
    if (!other.inside) return true;
    const Point corner = sim::solid_point(parts[fixed].final_pose.inverse() * (parts[moving].final_pose * mesh.vertices.front()));
    return std::sqrt(other.surface->squared_distance(corner)) <= tolerance || !other.contains(corner);
  };
  InterferenceCheck check;
  for (PartIndex i = 0; i < parts.size(); ++i) {
    for (PartIndex j = i + 1; j < parts.size(); ++j) {
      if (boxes[i].isEmpty() || boxes[j].isEmpty()) continue;
      const Eigen::AlignedBox3d common = boxes[i].intersection(boxes[j]);
      if (common.isEmpty() || common.sizes().minCoeff() <= tolerance) continue;
      if (clear_to_bullet(i, j) || clear_to_bullet(j, i)) continue;
      const Pose &pi = parts[i].final_pose, &pj = parts[j].final_pose;
      std::vector<Vec3> inside;
      const double depth = std::max(depth_into(solid(i), pi, solid(j), pj, common, tolerance, inside),
                                    depth_into(solid(j), pj, solid(i), pi, common, tolerance, inside));
      if (depth > tolerance) check.overlaps.push_back({i, j, depth, std::move(inside)});
    }
  }
  for (PartIndex i = 0; i < parts.size(); ++i) {
    const auto it = product.meshes[i] ? solids.find(product.meshes[i].get()) : solids.end();
    if (it != solids.end() && !it->second->inside) check.not_closed.push_back(i);
  }
  return check;
}

std::string describe(const Product& product, const Interference& interference) {
  char depth[32];
  std::snprintf(depth, sizeof depth, "%.1f mm", interference.depth * 1000);
  return product.parts()[interference.part2].name + " overlaps " + product.parts()[interference.part1].name + " by " +
         depth + " in the finished product; check its link offsets";
}

}  // namespace twin
