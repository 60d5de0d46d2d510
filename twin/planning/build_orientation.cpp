#include "twin/planning/build_orientation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "twin/geometry/placement.hpp"

namespace twin {
namespace {

Quat about(const Vec3& axis, double degrees) { return Quat(Eigen::AngleAxisd(degrees * M_PI / 180, axis)); }

bool bounded_by_overlaps(const Plan& plan) {
  return std::any_of(plan.findings.begin(), plan.findings.end(), [](const Finding& f) { return f.kind == "search-bound"; });
}

// Whether the whole product, every fastening made, stands on the station as it lies.
bool stands_finished(const LoadedProduct& product, const PlannerOptions& options) {
  const StabilityAnalysis stability(product, options.stand);
  std::vector<PlacedPart> placed;
  for (PartIndex p = 0; p < product.product.parts().size(); ++p) placed.push_back({p, product.product.parts()[p].final_pose});
  std::vector<bool> fastened;
  for (const auto& c : product.product.connections()) fastened.push_back(c.joint.fastens());
  return !stability.check(placed, {}, fastened).has_value();
}

std::string parts_in(const Plan& plan, std::size_t parts) {
  return std::to_string(plan.parts_placed()) + " of " + std::to_string(parts);
}

}  // namespace

const std::vector<BuildOrientation>& build_orientations() {
  // Y is up; a turn of 90 degrees about z takes +x up, so the product lies on its -x side;
  // 90 degrees about x takes +z down.
  static const std::vector<BuildOrientation> all{
      {"as finished", Quat::Identity()},
      {"upside down", about(Vec3::UnitX(), 180)},
      {"on its -x side", about(Vec3::UnitZ(), 90)},
      {"on its +x side", about(Vec3::UnitZ(), -90)},
      {"on its +z side", about(Vec3::UnitX(), 90)},
      {"on its -z side", about(Vec3::UnitX(), -90)},
  };
  return all;
}

LoadedProduct turned_product(const LoadedProduct& product, const Quat& turn) {
  LoadedProduct out = product;
  auto& parts = out.product.parts();
  Eigen::AlignedBox3d box;
  for (PartIndex i = 0; i < parts.size(); ++i) {
    const Pose& pose = parts[i].final_pose;
    const sim::TriangleMesh* mesh = i < out.meshes.size() ? out.meshes[i].get() : nullptr;
    if (!mesh) {
      box.extend(pose.translation());
      continue;
    }
    for (const auto& v : mesh->vertices) box.extend(pose * v);
  }
  const Vec3 centre = box.isEmpty() ? Vec3(Vec3::Zero()) : Vec3(box.center());
  Pose about_centre = Pose::Identity();
  about_centre.linear() = turn.normalized().toRotationMatrix();
  about_centre.translation() = centre - about_centre.linear() * centre;
  for (auto& part : parts) part.final_pose = about_centre * part.final_pose;
  set_on_surface(out.product, out.meshes);
  return out;
}

OrientedPlan plan_in_build_orientation(const LoadedProduct& product, SequencePlanner& sequence, PathPlanner& path,
                                       const PlannerOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const auto& orientations = build_orientations();
  OrientedPlan finished{plan_assembly(product, sequence, path, options), orientations.front(), product};
  if (finished.plan.complete || bounded_by_overlaps(finished.plan)) return finished;

  const std::size_t parts = product.product.parts().size();
  OrientedPlan best = std::move(finished);
  std::vector<std::string> tried{"parts in place " + best.orientation.name + ": " + parts_in(best.plan, parts)};
  for (std::size_t i = 1; i < orientations.size(); ++i) {
    if (options.stop && options.stop()) {
      tried.push_back(orientations[i].name + ": not tried, planning was told to stop");
      break;
    }
    PlannerOptions each = options;
    if (options.time_limit > 0) {
      each.time_limit = options.time_limit - std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (each.time_limit <= 0) {
        tried.push_back(orientations[i].name + ": not tried, the time limit came first");
        break;
      }
    }
    LoadedProduct turned = turned_product(product, orientations[i].turn);
    // Where the finished product would not stand so, no plan there is complete without a fixture.
    if (options.stability && !options.fixtures && !stands_finished(turned, options)) {
      tried.push_back(orientations[i].name + ": would not stand finished");
      continue;
    }
    Plan plan = plan_assembly(turned, sequence, path, each);
    tried.push_back(orientations[i].name + ": " + parts_in(plan, parts));
    if (plan.complete || plan.parts_placed() > best.plan.parts_placed()) {
      best = {std::move(plan), orientations[i], std::move(turned)};
      best.plan.orientation = orientations[i].name;
    }
    if (best.plan.complete) break;
  }
  std::string list;
  for (const auto& t : tried) list += (list.empty() ? "" : "; ") + t;
  const std::string& name = best.orientation.name;
  if (best.plan.complete) {
    best.plan.findings.push_back({"orientation", "built " + name + " (" + list + "); the cell cannot "
                                  "turn it over, so it is delivered " + name, {}});
  } else {
    best.plan.findings.push_back({"orientation", "no orientation builds it (" + list + "); the plan "
                                  "shown is " + name + "'s, which holds the most", {}});
  }
  return best;
}

}  // namespace twin
