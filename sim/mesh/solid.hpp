#pragma once
// A closed mesh as a solid, in its own frame (metres): its surface for distances, what lies
// inside it, and points over its surface. Volumes, not surfaces: two faces that overlap flat,
// or a face pushed into a finely tessellated one, show as points of one inside the other,
// where triangle against triangle sees only the shortest way out of two thin triangles.
// Used by the finished product's interference check (twin/planning/interference.*) and by
// the collision world's check of a concave part against a concave part.

#include <array>
#include <cstddef>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>

#include "sim/mesh/flat_regions.hpp"
#include "sim/mesh/triangle_mesh.hpp"

namespace sim {

using SolidKernel = CGAL::Simple_cartesian<double>;
using SolidPoint = SolidKernel::Point_3;

struct Solid {
  using Mesh = CGAL::Surface_mesh<SolidPoint>;
  using Tree = CGAL::AABB_tree<CGAL::AABB_traits<SolidKernel, CGAL::AABB_face_graph_triangle_primitive<Mesh>>>;
  using SideOf = CGAL::Side_of_triangle_mesh<Mesh, SolidKernel>;

  Mesh mesh;
  std::unique_ptr<Tree> surface;
  std::unique_ptr<SideOf> inside;  // null: the mesh is not closed, it has no inside
  double orientation = 1;          // -1: its faces are wound inwards
  // Its vertices, then points over each triangle at most 2 mm apart (coarser on large faces);
  // only where asked for (solid_of).
  std::vector<Eigen::Vector3d> samples;

  // Whether a point lies inside (false for a solid that has no inside); the second form for
  // a closed solid, with the point's nearest surface point and its face.
  bool contains(const SolidPoint& p) const;
  bool contains(const SolidPoint& p, const SolidPoint& nearest, Mesh::Face_index face) const;
  // How deep a point lies inside: its distance from the surface, where that is more than
  // `tolerance` and it is inside; 0 otherwise.
  double depth(const Eigen::Vector3d& p, double tolerance) const;
  // Its faces joined into flat regions; made when first asked (deepest_inside), once.
  const FlatRegions& flat_regions() const;

 private:
  mutable std::once_flag flat_once_;
  mutable std::unique_ptr<FlatRegions> flat_;
};

// A point of a triangle that lies inside a solid, and how deep.
struct DeepPoint {
  double depth = 0;  // m: its distance from the solid's surface
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

// How deep the triangle (corners in the solid's frame) goes into the solid, searched over the
// whole triangle, not at chosen points: it is cut into smaller triangles, and one is given up
// where no point of it can lie deeper than `tolerance` (its corners' distance from the face
// nearest its middle bounds every inner point's depth: the distance to a face is convex) or
// where it lies wholly outside (its middle outside, farther from the surface than any of its
// points is from the middle), or where it lies over one flat region of the surface, its
// corners within `tolerance` of the region's plane (FlatRegions: a sliver lying on a panel's face).
// Returns a point deeper than `tolerance` (with `deepest`, the deepest to within
// `resolution`; else the first), or nothing. Down to pieces of circumradius `resolution`: a point up to that much
// deeper than `tolerance` in a piece of that size may go unseen (never one deeper than
// tolerance + resolution). A solid without an inside holds nothing. `pieces_asked` counts the
// pieces whose nearest surface point was asked for (each a query of the surface's tree).
std::optional<DeepPoint> deepest_inside(const Solid& solid, const std::array<Eigen::Vector3d, 3>& triangle,
                                        double tolerance, double resolution, bool deepest = false,
                                        std::size_t* pieces_asked = nullptr);

inline SolidPoint solid_point(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

std::unique_ptr<Solid> solid_of(const TriangleMesh& mesh, bool with_samples = false);

}  // namespace sim
