#include "sim/mesh/flat_regions.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include <Eigen/Geometry>
#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>

namespace sim {
namespace {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;
using Point2 = bg::model::point<double, 2, bg::cs::cartesian>;
using Box2 = bg::model::box<Point2>;
using Entry = std::pair<Box2, std::uint32_t>;
using Vec2 = Eigen::Vector2d;

constexpr double kFlat = 1e-6;          // m: a face's corners this near the region's plane join it
constexpr double kParallel = 1 - 1e-6;  // cosine between a joining face's normal and the plane's
constexpr double kTouch = 1e-9;         // m: a boundary edge this near a shadow touches it

Eigen::Vector3d point_of(const FlatRegions::Mesh& mesh, FlatRegions::Mesh::Vertex_index v) {
  const auto& p = mesh.point(v);
  return {p.x(), p.y(), p.z()};
}

std::array<Eigen::Vector3d, 3> corners_of(const FlatRegions::Mesh& mesh, FlatRegions::Mesh::Face_index f) {
  const auto h = mesh.halfedge(f);
  return {point_of(mesh, mesh.source(h)), point_of(mesh, mesh.target(h)), point_of(mesh, mesh.target(mesh.next(h)))};
}

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

double point_segment_distance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

double segment_distance(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double o1 = cross(b - a, c - a), o2 = cross(b - a, d - a), o3 = cross(d - c, a - c), o4 = cross(d - c, b - c);
  if (((o1 < 0 && o2 > 0) || (o1 > 0 && o2 < 0)) && ((o3 < 0 && o4 > 0) || (o3 > 0 && o4 < 0))) return 0;
  return std::min({point_segment_distance(a, c, d), point_segment_distance(b, c, d), point_segment_distance(c, a, b),
                   point_segment_distance(d, a, b)});
}

// Inside or on the triangle; a triangle of no area holds nothing but its edges (asked apart).
bool in_triangle(const Vec2& p, const std::array<Vec2, 3>& t) {
  const double a = cross(t[1] - t[0], p - t[0]), b = cross(t[2] - t[1], p - t[1]), c = cross(t[0] - t[2], p - t[2]);
  return (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
}

bool touches(const Vec2& a, const Vec2& b, const std::array<Vec2, 3>& t) {
  if (in_triangle(a, t) || in_triangle(b, t)) return true;
  for (int i = 0; i < 3; ++i) {
    if (segment_distance(a, b, t[i], t[(i + 1) % 3]) <= kTouch) return true;
  }
  return false;
}

}  // namespace

struct FlatRegions::Region {
  Eigen::Vector3d normal, origin, u, v;  // the plane: through `origin`; u, v span it
  double deviation = 0;                  // m: its faces' corners at most this far from the plane
  std::vector<std::array<Vec2, 2>> boundary;
  bgi::rtree<Entry, bgi::rstar<16>> boundary_tree;

  Vec2 shadow(const Eigen::Vector3d& p) const { return {(p - origin).dot(u), (p - origin).dot(v)}; }
  double height(const Eigen::Vector3d& p) const { return (p - origin).dot(normal); }
};

FlatRegions::~FlatRegions() = default;

FlatRegions::FlatRegions(const Mesh& mesh) : mesh_(mesh), region_of_face_(mesh.number_of_faces(), -1) {
  const auto unit_normal = [&](Mesh::Face_index f) -> std::optional<Eigen::Vector3d> {
    const auto c = corners_of(mesh, f);
    const Eigen::Vector3d n = (c[1] - c[0]).cross(c[2] - c[0]);
    if (n.norm() <= 1e-18) return std::nullopt;
    return n.normalized();
  };
  std::vector<char> seen(mesh.number_of_faces(), 0);
  for (const auto seed : mesh.faces()) {
    if (seen[seed]) continue;
    seen[seed] = 1;
    const auto normal = unit_normal(seed);
    if (!normal) continue;
    auto region = std::make_unique<Region>();
    region->normal = *normal;
    region->origin = corners_of(mesh, seed)[0];
    region->u = normal->unitOrthogonal();
    region->v = normal->cross(region->u);
    std::vector<Mesh::Face_index> members{seed};
    for (std::size_t i = 0; i < members.size(); ++i) {
      for (const auto h : CGAL::halfedges_around_face(mesh.halfedge(members[i]), mesh)) {
        const auto next = mesh.face(mesh.opposite(h));
        if (next == Mesh::null_face() || seen[next]) continue;
        const auto n = unit_normal(next);
        if (!n || n->dot(*normal) < kParallel) continue;
        const auto c = corners_of(mesh, next);
        if (std::any_of(c.begin(), c.end(), [&](const Eigen::Vector3d& p) { return std::abs(region->height(p)) > kFlat; })) {
          continue;
        }
        seen[next] = 1;
        members.push_back(next);
        for (const auto& p : c) region->deviation = std::max(region->deviation, std::abs(region->height(p)));
      }
    }
    if (members.size() < 2) continue;  // the face alone: its own bound is as good
    const auto index = static_cast<std::int32_t>(regions_.size());
    for (const auto f : members) region_of_face_[f] = index;
    std::vector<Entry> entries;
    for (const auto f : members) {
      for (const auto h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh)) {
        const auto other = mesh.face(mesh.opposite(h));
        if (other != Mesh::null_face() && region_of_face_[other] == index) continue;
        const Vec2 a = region->shadow(point_of(mesh, mesh.source(h))), b = region->shadow(point_of(mesh, mesh.target(h)));
        entries.emplace_back(Box2(Point2(std::min(a.x(), b.x()), std::min(a.y(), b.y())),
                                  Point2(std::max(a.x(), b.x()), std::max(a.y(), b.y()))),
                             static_cast<std::uint32_t>(region->boundary.size()));
        region->boundary.push_back({a, b});
      }
    }
    region->boundary_tree = bgi::rtree<Entry, bgi::rstar<16>>(entries.begin(), entries.end());
    regions_.push_back(std::move(region));
  }
}

bool FlatRegions::within(Mesh::Face_index face, const std::array<Eigen::Vector3d, 3>& triangle, double distance) const {
  const auto index = region_of_face_.at(face);
  if (index < 0) return false;
  const Region& region = *regions_[static_cast<std::size_t>(index)];
  for (const auto& corner : triangle) {
    if (std::abs(region.height(corner)) + region.deviation > distance) return false;
  }
  const std::array<Vec2, 3> shadow{region.shadow(triangle[0]), region.shadow(triangle[1]), region.shadow(triangle[2])};
  // The middle's shadow inside the face (so inside the region), and no edge of the region's
  // outline or holes touching the shadow: the shadow is one piece, so all of it lies inside.
  std::array<Vec2, 3> f;
  const auto corners = corners_of(mesh_, face);
  for (int i = 0; i < 3; ++i) f[i] = region.shadow(corners[i]);
  const Vec2 middle = (shadow[0] + shadow[1] + shadow[2]) / 3;
  const double area = cross(f[1] - f[0], f[2] - f[0]);
  for (int i = 0; i < 3; ++i) {
    if (cross(f[(i + 1) % 3] - f[i], middle - f[i]) / area <= 1e-6) return false;
  }
  Box2 box(Point2(std::min({shadow[0].x(), shadow[1].x(), shadow[2].x()}) - kTouch,
                  std::min({shadow[0].y(), shadow[1].y(), shadow[2].y()}) - kTouch),
           Point2(std::max({shadow[0].x(), shadow[1].x(), shadow[2].x()}) + kTouch,
                  std::max({shadow[0].y(), shadow[1].y(), shadow[2].y()}) + kTouch));
  for (auto it = region.boundary_tree.qbegin(bgi::intersects(box)); it != region.boundary_tree.qend(); ++it) {
    const auto& edge = region.boundary[it->second];
    if (touches(edge[0], edge[1], shadow)) return false;
  }
  return true;
}

}  // namespace sim
