#include "sim/cell_sim/world_block.hpp"

#include <stdexcept>

namespace sim {
namespace {

Pose pose_at(const fb::Numbers& n, std::size_t first) {
  Pose p = Pose::Identity();
  p.translation() = Eigen::Vector3d(n[first], n[first + 1], n[first + 2]);
  p.linear() = Eigen::Quaterniond(n[first + 3], n[first + 4], n[first + 5], n[first + 6]).normalized().toRotationMatrix();
  return p;
}

std::vector<Pose> poses(const fb::Numbers& n) {
  if (n.size() % 7 != 0) throw SimError("a path needs seven numbers per pose");
  std::vector<Pose> out;
  for (std::size_t i = 0; i < n.size(); i += 7) out.push_back(pose_at(n, i));
  return out;
}

}  // namespace

WorldBlock::WorldBlock(std::string name, double real_time_factor, fb::CellBounds bounds, double clock_period_s,
                       std::chrono::milliseconds hire_wait)
    : FunctionBlock(std::move(name)), factor_(real_time_factor), clock_period_(clock_period_s), hire_wait_(hire_wait),
      policy_(bounds) {
  if (real_time_factor <= 0) throw std::invalid_argument("the real-time factor must be above 0");
  declare_input("REQUEST", {"request_id", "requester", "kind", "body_id"});
  declare_input("TICK");
  declare_input("ORDER_ENDED", {"order_id"});
  declare_input("HIRED", {"resource_id", "order_id"});
  declare_output("REPLY", {"request_id", "requester", "ok", "error", "collided", "start_time", "end_time"});
  declare_output("CLOCK", {"sim_time", "real_time_factor"});
  declare_output("REFUSED", {"refused", "last_refusal"});
}

double WorldBlock::now() const {
  return factor_ * std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
}

void WorldBlock::receive(const fb::Event& event) {
  if (event.name == "REQUEST") handle(event.data);
  if (event.name == "ORDER_ENDED") {
    for (const std::string& body : policy_.order_ended(fb::get<std::string>(event.data, "order_id"))) {
      if (world_.pose(body)) world_.remove(body);
    }
  }
  if (event.name == "HIRED") {
    const std::string resource = fb::get<std::string>(event.data, "resource_id"), order = fb::get<std::string>(event.data, "order_id");
    policy_.hired(resource, order);
    std::vector<Held> waiting;
    waiting.swap(held_);
    for (Held& h : waiting) {
      if (fb::get<std::string>(h.request, "requester") == resource && fb::get_or<std::string>(h.request, "order_id", "") == order) {
        handle(h.request, false);
      } else {
        held_.push_back(std::move(h));
      }
    }
  }
  publish_due();
}

void WorldBlock::handle(const fb::Data& d, bool may_wait) {
  const double start = now();
  fb::Data reply{{"request_id", d.at("request_id")}, {"requester", d.at("requester")}, {"ok", true},
                 {"start_time", start}, {"end_time", start}};
  double due = start;
  try {
    if (const std::string problem = policy_.problem_with(d, world_); !problem.empty()) {
      const std::string order = fb::get_or<std::string>(d, "order_id", ""), requester = fb::get<std::string>(d, "requester");
      if (may_wait && !order.empty() && !policy_.hired_by(requester, order) && policy_.has_bodies(requester) &&
          held_.size() < kMaxHeld) {
        held_.push_back({std::chrono::steady_clock::now() + hire_wait_, d});
        return;
      }
      emit("REFUSED", {{"refused", std::int64_t(++refused_)},
                       {"last_refusal", fb::get<std::string>(d, "requester") + " " +
                                            fb::get<std::string>(d, "request_id") + ": " + problem}});
      throw SimError(problem);
    }
    const std::string& kind = fb::get<std::string>(d, "kind");
    const std::string& id = fb::get<std::string>(d, "body_id");
    if (kind == "spawn") {
      // A requester's own body spawned again (a resource that restarted: its table, its
      // gripper, its base) is replaced.
      if (world_.pose(id) && policy_.owner_of(id) == fb::get<std::string>(d, "requester")) world_.remove(id);
      const fb::Numbers& h = fb::get<fb::Numbers>(d, "half_extents");
      const double scale = fb::get_or<double>(d, "mesh_scale", 1);
      world_.spawn({id, fb::get_or<std::string>(d, "mesh_uri", ""), Eigen::Vector3d(h.at(0), h.at(1), h.at(2)),
                    pose_at(fb::get<fb::Numbers>(d, "placement"), 0), fb::get_or<bool>(d, "is_static", false),
                    fb::get_or<std::string>(d, "scene", ""), fb::get_or<bool>(d, "fixture", false),
                    scale > 0 ? scale : 1});
      policy_.spawned(id, fb::get<std::string>(d, "requester"));
    } else if (kind == "remove") {
      world_.remove(id);
      policy_.removed(id);
    } else if (kind == "set_static" || kind == "set_movable") {
      world_.set_static(id, kind == "set_static");
    } else if (kind == "ping") {
      // Answered, and nothing else: a requester learns that its requests and cell-sim's
      // replies both reach it (DDS matches each endpoint pair on its own).
    } else if (kind == "move") {
      const MoveResult r = world_.move({id, fb::split_names(fb::get_or<std::string>(d, "carried", "")),
                                        poses(fb::get<fb::Numbers>(d, "path")), fb::get<double>(d, "speed"),
                                        fb::get_or<double>(d, "angular_speed", 0),
                                        fb::get_or<std::string>(d, "turning", ""), fb::get_or<std::string>(d, "into", "")});
      // A physical move is answered when the sim clock reaches its end. A virtual one is a
      // check, not work of the cell: answered at once, and it takes no sim time.
      if (world_.scene_of(id).empty()) due = start + r.duration;
      reply["end_time"] = due;
      reply["distance"] = r.distance;
      reply["collided"] = r.collided;
      reply["hit_body"] = r.hit_body;
      reply["hit_member"] = r.hit_member;
      reply["depth"] = r.depth;
    } else {
      throw SimError("unknown request kind '" + kind + "'");
    }
  } catch (const std::exception& e) {  // a bad request fails alone; the world goes on
    reply["ok"] = false;
    reply["error"] = std::string(e.what());
  }
  pending_.emplace(due, std::move(reply));
}

void WorldBlock::publish_due() {
  while (!held_.empty() && held_.front().until <= std::chrono::steady_clock::now()) {
    const fb::Data request = std::move(held_.front().request);
    held_.erase(held_.begin());
    handle(request, false);
  }
  const double t = now();
  while (!pending_.empty() && pending_.begin()->first <= t) {
    fb::Data reply = std::move(pending_.begin()->second);
    pending_.erase(pending_.begin());
    emit("REPLY", std::move(reply));
  }
  const auto wall = std::chrono::steady_clock::now();
  if (wall - last_clock_ >= clock_period_) {
    last_clock_ = wall;
    emit("CLOCK", {{"sim_time", t}, {"real_time_factor", factor_}});
  }
}

}  // namespace sim
