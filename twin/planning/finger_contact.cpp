#include "twin/planning/finger_contact.hpp"

#include <algorithm>

#include <CGAL/Intersections_3/Bbox_3_Triangle_3.h>
#include <CGAL/Simple_cartesian.h>

namespace twin {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;

Kernel::Point_3 point(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

bool apart(const CGAL::Bbox_3& a, const CGAL::Bbox_3& b) {
  for (int i = 0; i < 3; ++i) {
    if (a.max(i) < b.min(i) || b.max(i) < a.min(i)) return true;
  }
  return false;
}

}  // namespace

bool fingers_touch(const sim::TriangleMesh& part, const Grasp& grasp, const fb::GripperGeometry& gripper, double within) {
  // The part in the gripper's frame: the fingers close along x, their inner faces at
  // +-opening/2, and reach down along -y from the palm (services/node/gripper.hpp).
  const Pose to_gripper = grasp.gripper.inverse();
  std::vector<Eigen::Vector3d> v(part.vertices.size());
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = to_gripper * part.vertices[i];
  const double half = grasp.opening / 2, top = -gripper.palm_thickness / 2, bottom = top - gripper.finger_length;
  const double width = gripper.finger_width / 2;
  constexpr double kOnTheFace = 1e-6;  // a surface in the box's face plane, rounded
  for (const double side : {-1.0, 1.0}) {
    const double outer = side * (half + kOnTheFace), inner = side * (half - within);
    const CGAL::Bbox_3 pad(std::min(outer, inner), bottom, -width, std::max(outer, inner), top, width);
    const bool touched = std::any_of(part.triangles.begin(), part.triangles.end(), [&](const auto& t) {
      const Eigen::Vector3d &a = v[t[0]], &b = v[t[1]], &c = v[t[2]];
      const Kernel::Triangle_3 triangle(point(a), point(b), point(c));
      if (apart(pad, triangle.bbox())) return false;
      return !triangle.is_degenerate() && CGAL::do_intersect(pad, triangle);
    });
    if (!touched) return false;
  }
  return true;
}

}  // namespace twin
