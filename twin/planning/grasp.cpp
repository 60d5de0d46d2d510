#include "twin/planning/grasp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/convex_hull_2.h>

#include "twin/planning/finger_contact.hpp"

namespace twin {
namespace {

const char* const kAxis[] = {"x", "y", "z"};
// m the fingertips of a deep grasp stay short of the part's far side (and of what it sits on).
constexpr double kDeepGraspClearance = 0.002;

std::string side_name(int axis, double sign) {
  if (axis == 1) return sign > 0 ? "above" : "below";
  return std::string(sign > 0 ? "+" : "-") + kAxis[axis];
}

}  // namespace

std::vector<Grasp> grasps_for(const Eigen::AlignedBox3d& box, const Pose& final_pose, const Vec3& direction,
                              const fb::GripperGeometry& gripper) {
  int push_axis = 0;
  direction.cwiseAbs().maxCoeff(&push_axis);
  const double push_sign = direction[push_axis] > 0 ? 1.0 : -1.0;

  // The carriage's sides, best first: behind the push, above, then the rest.
  std::vector<std::pair<int, double>> sides{{push_axis, -push_sign}, {1, 1.0}};
  for (int axis : {0, 2, 1}) {
    for (double sign : {1.0, -1.0}) sides.emplace_back(axis, sign);
  }
  std::vector<std::pair<int, double>> unique_sides;
  for (const auto& s : sides) {
    const bool ahead = s.first == push_axis && s.second == push_sign;
    if (!ahead && std::find(unique_sides.begin(), unique_sides.end(), s) == unique_sides.end()) unique_sides.push_back(s);
  }

  const Vec3 size = box.sizes();
  std::vector<Grasp> out;
  for (const auto& [side_axis, side_sign] : unique_sides) {
    std::vector<int> closing;
    for (int a = 0; a < 3; ++a) {
      if (a != side_axis && size[a] <= gripper.max_opening) closing.push_back(a);
    }
    std::sort(closing.begin(), closing.end(), [&](int a, int b) { return size[a] < size[b]; });
    const double depth = size[side_axis];
    for (int close : closing) {
      Vec3 x = Vec3::Zero(), y = Vec3::Zero();
      x[close] = 1;
      y[side_axis] = side_sign;
      Pose world = Pose::Identity();
      world.linear().col(0) = x;
      world.linear().col(1) = y;
      world.linear().col(2) = x.cross(y);
      const std::string label = std::string("across ") + kAxis[close] + " from " + side_name(side_axis, side_sign);
      // Half-way into the part, then a quarter (out of a bore the part sinks into), then as
      // deep as the fingers and the part allow (low walls of a concave part the fingers would
      // miss half-way down: finger_contact.hpp).
      const double half = std::min(gripper.finger_length, depth / 2), quarter = std::min(gripper.finger_length, depth / 4);
      const double deep = std::min(gripper.finger_length, depth - kDeepGraspClearance);
      const auto add = [&](double reach, Grasp::Reach kind, const char* variant) {
        // The palm stands off the part's face so that the fingertips reach `reach` into it.
        world.translation() = box.center() + y * (depth / 2 + gripper.finger_length - reach + gripper.palm_thickness / 2);
        out.push_back({final_pose.inverse() * world, size[close], label + variant, kind});
      };
      add(half, Grasp::Reach::half, "");
      if (quarter < half) add(quarter, Grasp::Reach::shallow, ", shallow");
      if (deep > half + kDeepGraspClearance) add(deep, Grasp::Reach::deep, ", deep");
    }
  }
  return out;
}

std::vector<Grasp> off_centre_grasps(const Grasp& centred, const sim::TriangleMesh& part,
                                     const fb::GripperGeometry& gripper) {
  const Pose to_gripper = centred.gripper.inverse();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;  // along the fingers' width (z)
  for (const Vec3& v : part.vertices) {
    const double z = (to_gripper * v).z();
    lo = std::min(lo, z), hi = std::max(hi, z);
  }
  std::vector<Grasp> out;
  if (!(hi - lo >= 4 * gripper.finger_width)) return out;
  for (const double along : {lo + (hi - lo) / 4, hi - (hi - lo) / 4}) {
    Grasp moved = centred;
    moved.gripper = centred.gripper * Eigen::Translation3d(0, 0, along);
    const auto span = span_between_fingers(part, moved, gripper);
    if (!span || span->second - span->first > gripper.max_opening) continue;
    moved.gripper = moved.gripper * Eigen::Translation3d((span->first + span->second) / 2, 0, 0);
    moved.opening = span->second - span->first;
    moved.label += ", " + std::to_string(std::lround(std::abs(along) * 1000)) + " mm off-centre" + (along > 0 ? " (+)" : " (-)");
    out.push_back(std::move(moved));
  }
  return out;
}

double footprint_yaw(const std::vector<Vec3>& points) {
  using Point = CGAL::Exact_predicates_inexact_constructions_kernel::Point_2;
  std::vector<Point> footprint, hull;
  footprint.reserve(points.size());
  for (const Vec3& p : points) footprint.emplace_back(p.x(), p.z());
  CGAL::convex_hull_2(footprint.begin(), footprint.end(), std::back_inserter(hull));
  double best_area = std::numeric_limits<double>::infinity(), best_yaw = 0;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Point& a = hull[i];
    const Point& b = hull[(i + 1) % hull.size()];
    const double dx = b.x() - a.x(), dz = b.y() - a.y(), length = std::hypot(dx, dz);
    if (length == 0) continue;
    const double ux = dx / length, uz = dz / length;  // along the edge, and (-uz, ux) across it
    double lo_u = 0, hi_u = 0, lo_v = 0, hi_v = 0;
    for (const Point& q : hull) {
      const double u = (q.x() - a.x()) * ux + (q.y() - a.y()) * uz, v = -(q.x() - a.x()) * uz + (q.y() - a.y()) * ux;
      lo_u = std::min(lo_u, u), hi_u = std::max(hi_u, u), lo_v = std::min(lo_v, v), hi_v = std::max(hi_v, v);
    }
    const double area = (hi_u - lo_u) * (hi_v - lo_v);
    if (area < best_area - 1e-12) best_area = area, best_yaw = std::atan2(uz, ux);
  }
  return std::fmod(std::fmod(best_yaw, M_PI / 2) + M_PI / 2, M_PI / 2);
}

Pose unturn_by(double yaw) {
  Pose unturn = Pose::Identity();
  // About y, +yaw takes the direction at atan2(z, x) = yaw to the x axis.
  unturn.linear() = Eigen::AngleAxisd(yaw, Vec3::UnitY()).toRotationMatrix();
  return unturn;
}

std::vector<Grasp> turned_grasps_for(const Eigen::AlignedBox3d& turned_box, double yaw, const Pose& final_pose,
                                     const Vec3& direction, const fb::GripperGeometry& gripper) {
  // A grasp's pose in the part's frame is the same in either world.
  const Pose unturn = unturn_by(yaw);
  std::vector<Grasp> out = grasps_for(turned_box, unturn * final_pose, unturn.linear() * direction, gripper);
  const std::string turn = ", turned " + std::to_string(std::lround(yaw * 180 / M_PI)) + " deg";
  for (Grasp& g : out) g.label += turn;
  return out;
}

}  // namespace twin
