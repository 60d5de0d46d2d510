#include "twin/planning/ompl_path_planner.hpp"

#include <ompl/base/spaces/SE3StateSpace.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include <algorithm>
#include <mutex>

namespace twin {
namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;

constexpr double kClearance = 0.010;  // m

Pose to_pose(const ob::State* state) {
  const auto* s = state->as<ob::SE3StateSpace::StateType>();
  const auto& r = s->rotation();
  Pose p = Pose::Identity();
  p.linear() = Quat(r.w, r.x, r.y, r.z).normalized().toRotationMatrix();
  p.translation() = Vec3(s->getX(), s->getY(), s->getZ());
  return p;
}

void set_state(ob::ScopedState<ob::SE3StateSpace>& state, const Pose& pose) {
  state->setXYZ(pose.translation().x(), pose.translation().y(), pose.translation().z());
  const Quat q(pose.linear());
  state->rotation().w = q.w();
  state->rotation().x = q.x();
  state->rotation().y = q.y();
  state->rotation().z = q.z();
}

// Uniform positions; orientations mostly near the part's final one (a small random turn),
// otherwise uniform. Assembly motions seldom need a part turned far from how it ends up, and
// uniform SO(3) samples make narrow passages (under a ledge, between walls) rare finds.
class NearOrientationSampler : public ob::StateSampler {
 public:
  NearOrientationSampler(const ob::StateSpace* space, const Quat& goal, double near_fraction, double sigma)
      : ob::StateSampler(space), default_(space->allocDefaultStateSampler()), goal_(goal),
        near_fraction_(near_fraction), sigma_(sigma) {}

  void sampleUniform(ob::State* state) override {
    default_->sampleUniform(state);
    if (rng_.uniform01() >= near_fraction_) return;
    const Vec3 axis = Vec3(rng_.gaussian01(), rng_.gaussian01(), rng_.gaussian01()).normalized();
    const Quat q = goal_ * Quat(Eigen::AngleAxisd(rng_.gaussian(0, sigma_), axis));
    auto& r = state->as<ob::SE3StateSpace::StateType>()->rotation();
    r.w = q.w();
    r.x = q.x();
    r.y = q.y();
    r.z = q.z();
  }
  void sampleUniformNear(ob::State* state, const ob::State* near, double distance) override {
    default_->sampleUniformNear(state, near, distance);
  }
  void sampleGaussian(ob::State* state, const ob::State* mean, double stddev) override {
    default_->sampleGaussian(state, mean, stddev);
  }

 private:
  ob::StateSamplerPtr default_;
  Quat goal_;
  double near_fraction_;
  double sigma_;
};

}  // namespace

OmplPathPlanner::OmplPathPlanner(OmplOptions options) : options_(options) {
  // One seed for the process, set before OMPL makes its first generator: same input, same plan.
  static std::once_flag seeded;
  std::call_once(seeded, [&] {
    ompl::RNG::setSeed(options_.seed);
    ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
  });
}

std::optional<Trajectory> OmplPathPlanner::next(const AssemblyScene& scene, PartIndex part,
                                                const std::vector<Attempt>& tried) {
  const auto& directions = LinearPathPlanner::directions();
  if (tried.size() < directions.size()) return linear_.next(scene, part, tried);
  // Then one sampling run for each face the gripper can hold the part by.
  for (std::size_t k = tried.size() - directions.size(); k < directions.size(); ++k) {
    const auto grasps = scene.grasps(part, directions[k].second);
    const auto holding = std::find_if(grasps.begin(), grasps.end(), [&](const Grasp& g) { return scene.holds(part, g); });
    if (holding == grasps.end()) continue;
    if (auto t = sample_path(scene, part, *holding)) return t;
  }
  return std::nullopt;
}

std::optional<Trajectory> OmplPathPlanner::sample_path(const AssemblyScene& scene, PartIndex part,
                                                       const Grasp& grasp) const {
  const Pose goal = scene.product().product.parts()[part].final_pose;
  const HeldPart& held = scene.hold(part, grasp);
  const Eigen::AlignedBox3d part_box = scene.final_bounds(part);
  Eigen::AlignedBox3d around = scene.assembled_bounds();
  around.extend(part_box);

  // Start: the part at its final orientation, straight above its place, clear of everything.
  Pose start = goal;
  start.translation().y() += around.max().y() + kClearance - part_box.min().y();
  if (scene.collision_at(held.with_arm, goal, "goal") || scene.collision_at(held.with_arm, start, "start")) {
    return std::nullopt;
  }

  auto space = std::make_shared<ob::SE3StateSpace>();
  const double reach = part_box.sizes().maxCoeff() + options_.workspace_margin;
  ob::RealVectorBounds bounds(3);
  for (int i = 0; i < 3; ++i) {
    bounds.setLow(i, around.min()[i] - reach);
    bounds.setHigh(i, around.max()[i] + reach);
  }
  bounds.setLow(1, 0.0);
  bounds.setHigh(1, start.translation().y() + reach);
  space->setBounds(bounds);
  const Quat goal_rotation(goal.linear());
  space->setStateSamplerAllocator([goal_rotation, this](const ob::StateSpace* s) {
    return std::make_shared<NearOrientationSampler>(s, goal_rotation, options_.near_orientation_fraction,
                                                    options_.orientation_sigma);
  });

  og::SimpleSetup setup(space);
  std::size_t checks = 0;
  setup.setStateValidityChecker([&](const ob::State* state) {
    ++checks;
    return !scene.collision_at(held.with_arm, to_pose(state), "sample");
  });
  const auto budget = [&] {
    checks = 0;
    return ob::plannerOrTerminationCondition(ob::PlannerTerminationCondition([&] { return checks >= options_.max_checks; }),
                                             ob::timedPlannerTerminationCondition(options_.seconds));
  };
  // Motions are checked at about 1 mm.
  setup.getSpaceInformation()->setStateValidityCheckingResolution(
      std::min(1.0, scene.world().options().linear_step / space->getMaximumExtent()));
  ob::ScopedState<ob::SE3StateSpace> from(space), to(space);
  set_state(from, start);
  set_state(to, goal);
  setup.setStartAndGoalStates(from, to);
  setup.setPlanner(std::make_shared<og::RRTConnect>(setup.getSpaceInformation()));
  if (setup.solve(budget()) != ob::PlannerStatus::EXACT_SOLUTION) return std::nullopt;
  setup.simplifySolution(budget());

  Trajectory t;
  t.label = "ompl";
  t.retreat = options_.retreat;
  const auto& states = setup.getSolutionPath().getStates();
  for (std::size_t i = 0; i < states.size(); ++i) {
    const Pose p = to_pose(states[i]);
    const char* phase = i == 0 ? "approach" : (i + 1 == states.size() ? "insert" : "transit");
    t.waypoints.push_back({phase, p, p, true});
  }
  t.waypoints.back().part = goal;  // exactly, not to the planner's tolerance
  if (t.waypoints.size() >= 2) {
    const Vec3 last = goal.translation() - t.waypoints[t.waypoints.size() - 2].part.translation();
    if (last.norm() > 1e-9) t.direction = last.normalized();
  }
  t.waypoints.push_back({"release", goal, goal, false});
  t.waypoints.push_back({"retreat", goal, goal, false});
  t.hold_by(grasp);
  return t;
}

}  // namespace twin
