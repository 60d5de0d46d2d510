#include "sim/mesh/solid.hpp"

#include <algorithm>
#include <cmath>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/boost/graph/helpers.h>

namespace sim {
namespace {

constexpr double kSampleSpacing = 2e-3;  // m, at most between surface samples
constexpr int kMaxDivisions = 8;         // per triangle edge: large faces are sampled coarser
constexpr double kMovedFrom = 4;         // resolutions: a piece this large outside is moved off
constexpr double kOnSurface = 1e-9;      // m: a point this near the surface is on it

using Exact = CGAL::Exact_predicates_inexact_constructions_kernel;  // exact predicates

Exact::Point_3 exact_point(const SolidPoint& p) { return {p.x(), p.y(), p.z()}; }

// Whether the triangle, moved by `shift`, meets no face of the surface (with exact predicates:
// a face that only touches it meets it) and its middle is then outside. Then all of it is
// outside once moved (it is one piece), so each of its points lies outside or within |shift|
// of the surface: the way from the point to where it was moved crosses the surface.
bool clear_when_moved(const Solid& solid, const std::array<Eigen::Vector3d, 3>& triangle, const Eigen::Vector3d& shift) {
  std::array<Exact::Point_3, 3> moved;
  CGAL::Bbox_3 box;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d p = triangle[i] + shift;
    moved[i] = Exact::Point_3(p.x(), p.y(), p.z());
    box += moved[i].bbox();
  }
  const Exact::Triangle_3 piece(moved[0], moved[1], moved[2]);
  if (piece.is_degenerate()) return false;
  // The faces near it: the box widened well past rounding, so that a face that meets the piece
  // is among them though the box test is not exact.
  constexpr double kWiden = 1e-7;  // m
  box = CGAL::Bbox_3(box.xmin() - kWiden, box.ymin() - kWiden, box.zmin() - kWiden, box.xmax() + kWiden,
                     box.ymax() + kWiden, box.zmax() + kWiden);
  thread_local std::vector<Solid::Tree::Primitive_id> near;
  near.clear();
  solid.surface->all_intersected_primitives(box, std::back_inserter(near));
  for (const auto f : near) {
    const auto h = solid.mesh.halfedge(f);
    const Exact::Triangle_3 face(exact_point(solid.mesh.point(solid.mesh.source(h))), exact_point(solid.mesh.point(solid.mesh.target(h))),
                                 exact_point(solid.mesh.point(solid.mesh.target(solid.mesh.next(h)))));
    if (face.is_degenerate() || CGAL::do_intersect(piece, face)) return false;
  }
  return !solid.contains(solid_point((triangle[0] + triangle[1] + triangle[2]) / 3 + shift));
}

}  // namespace

// Where the point's nearest surface point is inside a face, the face's normal tells (the mesh
// is closed and consistently wound: Surface_mesh accepted every face); at an edge or a
// corner, a ray does (slower).
bool Solid::contains(const SolidPoint& p) const {
  if (!inside) return false;
  const auto [nearest, face] = surface->closest_point_and_primitive(p);
  return contains(p, nearest, face);
}

bool Solid::contains(const SolidPoint& p, const SolidPoint& nearest, Mesh::Face_index face) const {
  const auto h = mesh.halfedge(face);
  const SolidPoint &a = mesh.point(mesh.source(h)), &b = mesh.point(mesh.target(h)),
                   &c = mesh.point(mesh.target(mesh.next(h)));
  const SolidKernel::Vector_3 n = CGAL::cross_product(b - a, c - a);
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

double Solid::depth(const Eigen::Vector3d& p, double tolerance) const {
  if (!inside) return 0;
  const SolidPoint q = solid_point(p);
  const auto [nearest, face] = surface->closest_point_and_primitive(q);
  const double distance = std::sqrt(CGAL::squared_distance(q, nearest));
  return distance > tolerance && contains(q, nearest, face) ? distance : 0;
}

const FlatRegions& Solid::flat_regions() const {
  std::call_once(flat_once_, [&] { flat_ = std::make_unique<FlatRegions>(mesh); });
  return *flat_;
}

std::optional<DeepPoint> deepest_inside(const Solid& solid, const std::array<Eigen::Vector3d, 3>& triangle,
                                        double tolerance, double resolution, bool deepest, std::size_t* pieces_asked) {
  if (!solid.inside) return std::nullopt;
  std::optional<DeepPoint> found;
  std::vector<std::array<Eigen::Vector3d, 3>> pieces{triangle};
  while (!pieces.empty()) {
    const std::array<Eigen::Vector3d, 3> t = pieces.back();
    pieces.pop_back();
    const Eigen::Vector3d middle = (t[0] + t[1] + t[2]) / 3;
    const double radius = std::max({(t[0] - middle).norm(), (t[1] - middle).norm(), (t[2] - middle).norm()});
    const SolidPoint q = solid_point(middle);
    const auto [nearest, face] = solid.surface->closest_point_and_primitive(q);
    if (pieces_asked) ++*pieces_asked;
    const double distance = std::sqrt(CGAL::squared_distance(q, nearest));
    // Only a point deeper than this matters; the deepest is wanted to within the resolution.
    const double floor = deepest && found ? found->depth + resolution : tolerance;
    // No point of the piece lies deeper than its corners' distance from one face of the surface
    // (the distance to a triangle is convex, so it is largest at a corner), nor deeper than the
    // middle's depth (negative outside) plus the radius.
    const auto h = solid.mesh.halfedge(face);
    const SolidKernel::Triangle_3 nearest_face(solid.mesh.point(solid.mesh.source(h)), solid.mesh.point(solid.mesh.target(h)),
                                               solid.mesh.point(solid.mesh.target(solid.mesh.next(h))));
    double bound = 0;
    for (const auto& corner : t) bound = std::max(bound, CGAL::squared_distance(solid_point(corner), nearest_face));
    bound = std::sqrt(bound);
    if (bound <= floor || solid.flat_regions().within(face, t, floor)) continue;
    const bool in = solid.contains(q, nearest, face);
    if (std::min(bound, (in ? distance : -distance) + radius) <= floor) continue;
    // A large piece outside but for where it touches or grazes the surface (a face standing on
    // a face, a shaft's facet along a bore): is it clear, moved three quarters of the floor
    // outwards (away from the middle's nearest surface point; along the face's normal where
    // the middle lies on the face, as a facet on a bore's facet)?
    if (radius > kMovedFrom * resolution && (!in || distance < floor / 2)) {
      const auto n = CGAL::cross_product(nearest_face[1] - nearest_face[0], nearest_face[2] - nearest_face[0]);
      const Eigen::Vector3d outwards =
          distance > kOnSurface ? Eigen::Vector3d((middle - Eigen::Vector3d(nearest.x(), nearest.y(), nearest.z())) * ((in ? -1 : 1) / distance))
                                : Eigen::Vector3d(Eigen::Vector3d(n.x(), n.y(), n.z()).normalized() * solid.orientation);
      if (outwards.allFinite() && clear_when_moved(solid, t, outwards * (0.75 * floor))) continue;
    }
    // Kept when deeper than the deepest yet, though by less than the resolution: a point of
    // this piece is then at most its radius deeper than the answer.
    if (in && distance > (found ? found->depth : tolerance)) {
      found = DeepPoint{distance, middle};
      if (!deepest) return found;
    }
    if (radius <= resolution) continue;
    const Eigen::Vector3d ab = (t[0] + t[1]) / 2, bc = (t[1] + t[2]) / 2, ca = (t[2] + t[0]) / 2;
    pieces.push_back({t[0], ab, ca});
    pieces.push_back({ab, t[1], bc});
    pieces.push_back({ca, bc, t[2]});
    pieces.push_back({ab, bc, ca});
  }
  return found;
}

std::unique_ptr<Solid> solid_of(const TriangleMesh& source, bool with_samples) {
  auto s = std::make_unique<Solid>();
  std::vector<Solid::Mesh::Vertex_index> vertices;
  vertices.reserve(source.vertices.size());
  for (const auto& v : source.vertices) {
    vertices.push_back(s->mesh.add_vertex(solid_point(v)));
    if (with_samples) s->samples.push_back(v);
  }
  bool manifold = true;
  for (const auto& t : source.triangles) {
    if (s->mesh.add_face(vertices[t[0]], vertices[t[1]], vertices[t[2]]) == Solid::Mesh::null_face()) manifold = false;
    if (!with_samples) continue;
    const Eigen::Vector3d &a = source.vertices[t[0]], &b = source.vertices[t[1]], &c = source.vertices[t[2]];
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int n = std::clamp(static_cast<int>(std::ceil(longest / kSampleSpacing)), 1, kMaxDivisions);
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; i + j <= n; ++j) {
        if ((i == 0 && j == 0) || i == n || j == n) continue;  // the corners are in already
        s->samples.push_back(a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n));
      }
    }
  }
  s->surface = std::make_unique<Solid::Tree>(faces(s->mesh).first, faces(s->mesh).second, s->mesh);
  if (manifold && CGAL::is_closed(s->mesh)) {
    s->inside = std::make_unique<Solid::SideOf>(*s->surface);
    double volume = 0;  // signed: positive when wound outwards
    for (const auto& t : source.triangles) {
      volume += source.vertices[t[0]].dot(source.vertices[t[1]].cross(source.vertices[t[2]]));
    }
    s->orientation = volume < 0 ? -1 : 1;
  }
  return s;
}

}  // namespace sim
