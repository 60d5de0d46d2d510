#include "deploy/cellctl/physical_scene.hpp"

#include <cmath>
#include <optional>

#include "sim/world/motion_time.hpp"

namespace cellctl {
namespace {

using nlohmann::json;

std::optional<Eigen::Isometry3d> isometry(const cell::Pose& p) {
  const Eigen::Vector3d t(p.position().x(), p.position().y(), p.position().z());
  Eigen::Quaterniond q(p.qw(), p.qx(), p.qy(), p.qz());
  if (!t.allFinite() || !q.coeffs().allFinite() || q.norm() < 1e-9) return std::nullopt;
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = q.normalized().toRotationMatrix();
  out.translation() = t;
  return out;
}

// Millimetres and a few decimals of a quaternion are what a view needs, in short JSON.
double shortened(double v) { return std::round(v * 1e5) / 1e5; }

json pose_json(const Eigen::Isometry3d& p) {
  const Eigen::Quaterniond q(p.linear());
  const Eigen::Vector3d& t = p.translation();
  return {shortened(t.x()), shortened(t.y()), shortened(t.z()), shortened(q.w()), shortened(q.x()), shortened(q.y()),
          shortened(q.z())};
}

// Where a motion has its body at `t`: along the segment it is on, in a straight line and
// the shortest turn, as cell-sim moves it.
Eigen::Isometry3d pose_at(const std::vector<double>& times, const std::vector<Eigen::Isometry3d>& poses, double t) {
  if (t <= times.front()) return poses.front();
  for (std::size_t i = 1; i < times.size(); ++i) {
    if (t >= times[i]) continue;
    const double f = (t - times[i - 1]) / (times[i] - times[i - 1]);
    const Eigen::Quaterniond a(poses[i - 1].linear()), b(poses[i].linear());
    Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
    out.linear() = a.slerp(f, b).toRotationMatrix();
    out.translation() = poses[i - 1].translation() + f * (poses[i].translation() - poses[i - 1].translation());
    return out;
  }
  return poses.back();
}

}  // namespace

bool PhysicalScene::take(const cell::SimRequest& request, double sim_now) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::string kind = request.kind().to_string();
  if (kind == "spawn") return spawn(request);
  if (kind == "remove") return bodies_.erase(request.body_id().to_string()) > 0;
  if (kind == "move") return move(request, sim_now);
  return false;
}

bool PhysicalScene::spawn(const cell::SimRequest& r) {
  const std::string id = r.body_id().to_string();
  if (id.empty() || r.scene().size() > 0) return false;
  if (bodies_.size() >= kMaxBodies && !bodies_.count(id)) return false;
  const auto placement = isometry(r.placement());
  const Eigen::Vector3d half(r.half_extents().x(), r.half_extents().y(), r.half_extents().z());
  if (!placement || !half.allFinite() || half.minCoeff() < 0) return false;
  Body body;
  body.mesh = r.mesh_uri().size() > 0;
  // A twin spawns its order's parts as their order (requester), a hired resource names it.
  body.order = r.order_id().size() > 0 ? r.order_id().to_string() : body.mesh ? r.requester().to_string() : "";
  body.owner = body.order.empty() ? r.requester().to_string() : "";
  body.half_extents = half;
  body.pose = body.before = *placement;
  bodies_[id] = std::move(body);  // a resource that restarted spawns its own bodies again
  return true;
}

bool PhysicalScene::move(const cell::SimRequest& r, double sim_now) {
  if (r.path().empty() || !(r.speed() > 0) || !std::isfinite(r.speed()) || !(r.angular_speed() >= 0)) return false;
  auto mover = bodies_.find(r.body_id().to_string());
  if (mover == bodies_.end()) {
    const auto start = isometry(r.path().front());
    if (!start || !resources_.count(r.requester().to_string()) || bodies_.size() >= kMaxBodies) return false;
    Body body;
    body.owner = r.requester().to_string();
    body.pose = body.before = *start;
    mover = bodies_.emplace(r.body_id().to_string(), std::move(body)).first;
  }
  Motion motion{{sim_now}, {mover->second.pose}};
  for (const cell::Pose& p : r.path()) {
    const auto next = isometry(p);
    if (!next) return false;
    motion.times.push_back(motion.times.back() +
                           sim::segment_duration(motion.poses.back(), *next, r.speed(), r.angular_speed()));
    motion.poses.push_back(*next);
  }
  std::vector<std::string> moved{mover->first};
  // What it carries keeps its place on it.
  for (const auto& id : r.carried()) {
    const auto carried = bodies_.find(id.to_string());
    if (carried == bodies_.end() || carried == mover) continue;
    const Eigen::Isometry3d on_it = mover->second.pose.inverse() * carried->second.pose;
    Body& c = carried->second;
    c.before = c.pose;
    c.motion.times = motion.times;
    c.motion.poses.clear();
    for (const auto& p : motion.poses) c.motion.poses.push_back(p * on_it);
    c.pose = c.motion.poses.back();
    moved.push_back(carried->first);
  }
  Body& m = mover->second;
  m.before = m.pose;
  m.pose = motion.poses.back();
  m.motion = std::move(motion);
  if (moving_.size() < kMaxMovesUnanswered) moving_[r.request_id().to_string()] = std::move(moved);
  return true;
}

bool PhysicalScene::take(const cell::SimReply& reply) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = moving_.find(reply.request_id().to_string());
  if (it == moving_.end()) return false;
  for (const auto& id : it->second) {
    const auto body = bodies_.find(id);
    if (body == bodies_.end() || body->second.motion.times.empty()) continue;
    Body& b = body->second;
    if (!reply.ok()) {  // refused: it did not move
      b.pose = b.before;
      b.motion = {};
      continue;
    }
    const double shift = reply.start_time() - b.motion.times.front();
    if (std::isfinite(shift)) {
      for (double& t : b.motion.times) t += shift;
    }
    if (reply.collided() && std::isfinite(reply.end_time()) && reply.end_time() < b.motion.times.back()) {
      // It stopped where it hit.
      b.pose = pose_at(b.motion.times, b.motion.poses, reply.end_time());
      std::size_t kept = 1;
      while (kept < b.motion.times.size() && b.motion.times[kept] < reply.end_time()) ++kept;
      b.motion.times.resize(kept);
      b.motion.poses.resize(kept);
      b.motion.times.push_back(reply.end_time());
      b.motion.poses.push_back(b.pose);
    }
  }
  moving_.erase(it);
  return true;
}

json PhysicalScene::bodies(double sim_now) const {
  std::lock_guard<std::mutex> lock(mutex_);
  json out = json::array();
  for (const auto& [id, b] : bodies_) {
    json body{{"id", id},
              {"owner", b.owner},
              {"order", b.order},
              {"half_extents", {b.half_extents.x(), b.half_extents.y(), b.half_extents.z()}},
              {"mesh", b.mesh},
              {"pose", pose_json(b.pose)}};
    if (!b.motion.times.empty() && b.motion.times.back() > sim_now) {
      json poses = json::array();
      for (const auto& p : b.motion.poses) poses.push_back(pose_json(p));
      body["motion"] = {{"t", b.motion.times}, {"poses", std::move(poses)}};
    }
    out.push_back(std::move(body));
  }
  return out;
}

std::size_t PhysicalScene::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return bodies_.size();
}

}  // namespace cellctl
