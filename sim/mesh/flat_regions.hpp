#pragma once
// The flat regions of a closed mesh's surface: faces joined across their shared edges while
// they lie in one plane (a panel's face of thousands of triangles around its holes), each with
// its boundary (outline and holes) in the plane's coordinates.
//
// What it proves: a point whose shadow on a region's plane falls inside the region lies no
// farther from the surface than from the plane. So a triangle lying on a finely triangulated
// flat face, whose nearest single face is small and whose corners lie beyond it, can be known
// to lie within a distance of the surface at once, where deepest_inside would cut it down to
// its resolution (a 106 x 5 mm sliver of one panel lying on another: 16 000 distance queries).

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>

namespace sim {

class FlatRegions {
 public:
  using Mesh = CGAL::Surface_mesh<CGAL::Simple_cartesian<double>::Point_3>;

  explicit FlatRegions(const Mesh& mesh);  // kept: it must outlive the regions
  ~FlatRegions();

  // Whether every point of the triangle (in the mesh's frame) lies within `distance` of the
  // surface because it lies over the flat region that holds `face` (the face nearest a point of
  // the triangle): the triangle's corners within `distance` of the region's plane, the shadow of
  // its middle inside `face`, and no edge of the region's boundary touching its shadow. False
  // where that is not shown (a face of no region of two or more faces, among others).
  bool within(Mesh::Face_index face, const std::array<Eigen::Vector3d, 3>& triangle, double distance) const;

  std::size_t regions() const { return regions_.size(); }

 private:
  struct Region;
  const Mesh& mesh_;
  std::vector<std::int32_t> region_of_face_;  // -1: the face is alone in its plane
  std::vector<std::unique_ptr<Region>> regions_;
};

}  // namespace sim
