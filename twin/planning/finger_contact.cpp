#include "twin/planning/finger_contact.hpp"

#include <algorithm>
#include <limits>
#include <vector>

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

// The polygon's part on the side of the plane where `inside` is not negative (Sutherland and
// Hodgman's clipping, one plane).
template <typename Inside>
std::vector<Eigen::Vector3d> clipped(const std::vector<Eigen::Vector3d>& polygon, Inside inside) {
  std::vector<Eigen::Vector3d> out;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector3d& a = polygon[i];
    const Eigen::Vector3d& b = polygon[(i + 1) % polygon.size()];
    const double da = inside(a), db = inside(b);
    if (da >= 0) out.push_back(a);
    if ((da < 0) != (db < 0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  return out;
}

}  // namespace

std::optional<std::pair<double, double>> span_between_fingers(const sim::TriangleMesh& part, const Grasp& grasp,
                                                              const fb::GripperGeometry& gripper) {
  const auto v = in_gripper_frame(part, grasp);
  const double top = -gripper.palm_thickness / 2, bottom = top - gripper.finger_length, width = gripper.finger_width / 2;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& t : part.triangles) {
    std::vector<Eigen::Vector3d> p{v[t[0]], v[t[1]], v[t[2]]};
    const auto [min, max] = std::minmax({p[0].z(), p[1].z(), p[2].z()});
    if (max < -width || min > width) continue;
    p = clipped(p, [&](const Eigen::Vector3d& q) { return top - q.y(); });
    p = clipped(p, [&](const Eigen::Vector3d& q) { return q.y() - bottom; });
    p = clipped(p, [&](const Eigen::Vector3d& q) { return width - q.z(); });
    p = clipped(p, [&](const Eigen::Vector3d& q) { return q.z() + width; });
    for (const auto& q : p) lo = std::min(lo, q.x()), hi = std::max(hi, q.x());
  }
  if (lo > hi) return std::nullopt;
  return std::make_pair(lo, hi);
}

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
