#include "twin/planning/finger_contact.hpp"

#include <algorithm>

#include <CGAL/Intersections_3/Bbox_3_Triangle_3.h>
#include <CGAL/Simple_cartesian.h>

namespace twin {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;

// The part's vertices in the gripper's frame: the fingers close along x, their inner faces at
// +-opening/2, and reach down along -y from the palm (services/node/gripper.hpp).
std::vector<Eigen::Vector3d> in_gripper_frame(const sim::TriangleMesh& part, const Grasp& grasp) {
  const Pose to_gripper = grasp.gripper.inverse();
  std::vector<Eigen::Vector3d> v(part.vertices.size());
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = to_gripper * part.vertices[i];
  return v;
}

// Whether a triangle of `part` from `first` on meets `box` (`v`: its vertices in the box's frame).
bool meets(const sim::TriangleMesh& part, const std::vector<Eigen::Vector3d>& v, std::size_t first, const CGAL::Bbox_3& box) {
  return std::any_of(part.triangles.begin() + static_cast<std::ptrdiff_t>(first), part.triangles.end(), [&](const auto& t) {
    const auto point = [&](std::uint32_t i) { return Kernel::Point_3(v[i].x(), v[i].y(), v[i].z()); };
    const Kernel::Triangle_3 triangle(point(t[0]), point(t[1]), point(t[2]));
    return CGAL::do_overlap(box, triangle.bbox()) && !triangle.is_degenerate() && CGAL::do_intersect(box, triangle);
  });
}

}  // namespace

bool fingers_touch(const sim::TriangleMesh& part, const Grasp& grasp, const fb::GripperGeometry& gripper, double within) {
  const auto v = in_gripper_frame(part, grasp);
  const double half = grasp.opening / 2, top = -gripper.palm_thickness / 2, bottom = top - gripper.finger_length;
  const double width = gripper.finger_width / 2;
  constexpr double kOnTheFace = 1e-6;  // a surface in the box's face plane, rounded
  for (const double side : {-1.0, 1.0}) {
    const double outer = side * (half + kOnTheFace), inner = side * (half - within);
    if (!meets(part, v, 0, CGAL::Bbox_3(std::min(outer, inner), bottom, -width, std::max(outer, inner), top, width))) {
      return false;
    }
  }
  return true;
}

bool gripper_clear_of(const sim::TriangleMesh& part, std::size_t first_triangle, const Grasp& grasp,
                      const fb::GripperGeometry& gripper, double tolerance) {
  const auto v = in_gripper_frame(part, grasp);
  for (const auto& box : fb::gripper_boxes(gripper, grasp.opening)) {
    const Eigen::Vector3d c = box.pose.translation(), h = (box.half_extents.array() - tolerance).max(0).matrix();
    if (meets(part, v, first_triangle, CGAL::Bbox_3(c.x() - h.x(), c.y() - h.y(), c.z() - h.z(), c.x() + h.x(), c.y() + h.y(),
                                                    c.z() + h.z()))) {
      return false;
    }
  }
  return true;
}

}  // namespace twin
