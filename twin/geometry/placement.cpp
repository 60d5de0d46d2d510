#include "twin/geometry/placement.hpp"

#include <cmath>
#include <deque>
#include <limits>
#include <sstream>

namespace twin {
namespace {

Vec3 world_point(const Product& product, PartIndex part, const std::string& interface) {
  return product.parts()[part].final_pose * (*product.interface_of(part, interface))->position;
}

std::string format_point(const Vec3& p) {
  std::ostringstream out;
  out.precision(6);
  out << "(" << p.x() << ", " << p.y() << ", " << p.z() << ") m";
  return out.str();
}

}  // namespace

void place_parts(Product& product, const PlacementOptions& options) {
  auto& parts = product.parts();
  if (parts.empty()) throw DescriptionError({product.source().string(), 0, ""}, "the product has no parts");

  std::vector<bool> placed(parts.size(), false);
  std::deque<PartIndex> frontier = {0};
  parts[0].final_pose = Pose::Identity();
  parts[0].final_pose.linear() = parts[0].orientation.toRotationMatrix();
  placed[0] = true;

  while (!frontier.empty()) {
    const PartIndex here = frontier.front();
    frontier.pop_front();
    for (std::size_t ci : product.connections_of(here)) {
      const Connection& c = product.connections()[ci];
      const bool forward = c.part1 == here;
      const PartIndex there = forward ? c.part2 : c.part1;
      const std::string& here_interface = forward ? c.interface1 : c.interface2;
      const std::string& there_interface = forward ? c.interface2 : c.interface1;
      const Vec3 target = world_point(product, here, here_interface);

      if (!placed[there]) {
        DigitalPart& p = parts[there];
        p.final_pose = Pose::Identity();
        p.final_pose.linear() = p.orientation.toRotationMatrix();
        p.final_pose.translation() = target - p.final_pose.linear() * (*product.interface_of(there, there_interface))->position;
        placed[there] = true;
        frontier.push_back(there);
        continue;
      }
      const Vec3 actual = world_point(product, there, there_interface);
      if ((actual - target).norm() > options.loop_tolerance) {
        throw DescriptionError(
            c.where, "link closes a loop that does not fit: it puts '" + parts[there].name + "." +
                         there_interface + "' at " + format_point(target) + ", the other links put it at " +
                         format_point(actual) + " (" + std::to_string((actual - target).norm() * 1000) +
                         " mm apart)");
      }
    }
  }

  std::vector<std::string> unreached;
  for (PartIndex i = 0; i < parts.size(); ++i) {
    if (!placed[i]) unreached.push_back(parts[i].name);
  }
  if (!unreached.empty()) {
    std::string names;
    for (std::size_t i = 0; i < unreached.size() && i < 10; ++i) names += (i ? ", " : "") + unreached[i];
    if (unreached.size() > 10) names += ", ... (" + std::to_string(unreached.size() - 10) + " more)";
    const PartIndex first = *product.find_part_by_name(unreached.front());
    throw DescriptionError(parts[first].where, std::to_string(unreached.size()) +
                                                   " part(s) not reached by any link from '" +
                                                   parts[0].name + "': " + names);
  }
}

void set_on_surface(Product& product, const PartMeshes& meshes) {
  double lowest = std::numeric_limits<double>::infinity();
  for (PartIndex i = 0; i < product.parts().size(); ++i) {
    const Pose& pose = product.parts()[i].final_pose;
    const sim::TriangleMesh* mesh = i < meshes.size() ? meshes[i].get() : nullptr;
    if (!mesh) lowest = std::min(lowest, pose.translation().y());
    else for (const auto& v : mesh->vertices) lowest = std::min(lowest, (pose * v).y());
  }
  if (!std::isfinite(lowest)) return;
  for (auto& part : product.parts()) part.final_pose.translation().y() -= lowest;
}

}  // namespace twin
