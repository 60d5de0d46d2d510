#include "twin/planning/interference.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

namespace twin {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, CGAL::AABB_face_graph_triangle_primitive<Mesh>>>;
using SideOf = CGAL::Side_of_triangle_mesh<Mesh, Kernel>;

constexpr double kSampleSpacing = 2e-3;  // m, at most between surface samples
constexpr int kMaxDivisions = 8;         // per triangle edge: large faces are sampled coarser

// A mesh as a solid, in its own frame: its surface for distances, what lies inside it (when
// the mesh is closed), and points over its surface. Built once per mesh, shared by the parts
// that use it.
struct Solid {
  Mesh mesh;
  std::unique_ptr<Tree> surface;
  std::unique_ptr<SideOf> inside;  // null: the mesh is not closed, it has no inside
  double orientation = 1;          // -1: its faces are wound inwards
  std::vector<Vec3> samples;

  // Whether a point lies inside. Where its nearest surface point is inside a face, the face's
  // normal tells (the mesh is closed and consistently wound: Surface_mesh accepted every
  // face); at an edge or a corner, a ray does (slower).
  bool contains(const Point& p) const {
    const auto [nearest, face] = surface->closest_point_and_primitive(p);
    const auto h = mesh.halfedge(face);
    const Point &a = mesh.point(mesh.source(h)), &b = mesh.point(mesh.target(h)),
                &c = mesh.point(mesh.target(mesh.next(h)));
    const Kernel::Vector_3 n = CGAL::cross_product(b - a, c - a);
    const double area2 = n.squared_length();
    if (area2 > 0) {
      // Barycentric coordinates of the nearest point: all clearly above 0 inside the face.
      const double u = CGAL::cross_product(c - b, nearest - b) * n / area2,
                   v = CGAL::cross_product(a - c, nearest - c) * n / area2, w = 1 - u - v;
      constexpr double kInside = 1e-6;
      if (u > kInside && v > kInside && w > kInside) return orientation * ((p - nearest) * n) < 0;
    }
    return (*inside)(p) == CGAL::ON_BOUNDED_SIDE;
  }
};

Point point(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

std::unique_ptr<Solid> solid_of(const sim::TriangleMesh& source) {
  auto s = std::make_unique<Solid>();
  std::vector<Mesh::Vertex_index> vertices;
  vertices.reserve(source.vertices.size());
  for (const auto& v : source.vertices) {
    vertices.push_back(s->mesh.add_vertex(point(v)));
    s->samples.push_back(v);
  }
  bool manifold = true;
  for (const auto& t : source.triangles) {
    if (s->mesh.add_face(vertices[t[0]], vertices[t[1]], vertices[t[2]]) == Mesh::null_face()) manifold = false;
    // Points over the triangle, kSampleSpacing apart at most (coarser on large faces).
    const Vec3 &a = source.vertices[t[0]], &b = source.vertices[t[1]], &c = source.vertices[t[2]];
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int n = std::clamp(static_cast<int>(std::ceil(longest / kSampleSpacing)), 1, kMaxDivisions);
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; i + j <= n; ++j) {
        if ((i == 0 && j == 0) || i == n || j == n) continue;  // the corners are in already
        s->samples.push_back(a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n));
      }
    }
  }
  s->surface = std::make_unique<Tree>(faces(s->mesh).first, faces(s->mesh).second, s->mesh);
  if (manifold && CGAL::is_closed(s->mesh)) {
    s->inside = std::make_unique<SideOf>(*s->surface);
    double volume = 0;  // signed: positive when wound outwards
    for (const auto& t : source.triangles) {
      volume += source.vertices[t[0]].dot(source.vertices[t[1]].cross(source.vertices[t[2]]));
    }
    s->orientation = volume < 0 ? -1 : 1;
  }
  return s;
}

// How deep a's surface reaches into b, each at its pose: the largest distance from b's
// surface of a sample of a's that lies inside b. Only samples farther than the tolerance
// (and than the deepest so far) from b's surface are asked whether they are inside.
// `common`: where the two parts' boxes overlap, in the product's frame.
double depth_into(const Solid& a, const Pose& a_pose, const Solid& b, const Pose& b_pose,
                  const Eigen::AlignedBox3d& common, double tolerance) {
  if (!b.inside) return 0;
  const Pose to_b = b_pose.inverse();
  double deepest = 0;
  Point hint = b.mesh.point(*b.mesh.vertices().begin());
  for (const Vec3& sample : a.samples) {
    const Vec3 in_product = a_pose * sample;
    if (!common.contains(in_product)) continue;
    const Vec3 p = to_b * in_product;
    // Samples come a triangle at a time: the last nearest point is a good hint.
    hint = b.surface->closest_point(point(p), hint);
    const double distance = std::sqrt(CGAL::squared_distance(point(p), hint));
    if (distance <= std::max(tolerance, deepest)) continue;
    if (b.contains(point(p))) deepest = distance;
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
    if (!s) s = solid_of(*product.meshes[i]);
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
    if (fresh) body->second.add_mesh("part", mesh, Pose::Identity(), options.shape_margin);
    if (!world) world.emplace(options);
    const sim::BodyId other_body = world->add_static_mesh(parts[fixed].name, product.meshes[fixed], parts[fixed].final_pose);
    const bool hit = world->penetration(body->second, parts[moving].final_pose).has_value();
    world->remove(other_body);
    if (hit) return false;
    // Wholly inside a volume is a deep hit; inside a triangle surface is no contact at all.
    if (is_volume(*product.meshes[fixed])) return true;
    const Solid& other = solid(fixed);
    if (!other.inside) return true;
    const Point corner = point(parts[fixed].final_pose.inverse() * (parts[moving].final_pose * mesh.vertices.front()));
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
      const double depth = std::max(depth_into(solid(i), pi, solid(j), pj, common, tolerance),
                                    depth_into(solid(j), pj, solid(i), pi, common, tolerance));
      if (depth > tolerance) check.overlaps.push_back({i, j, depth});
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
