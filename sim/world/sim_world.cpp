#include "sim/world/sim_world.hpp"

#include "sim/world/motion_time.hpp"

#include <algorithm>

namespace sim {
SimWorld::SimWorld(CollisionOptions options) : options_(options) { scene(""); }

// A new virtual scene starts with every fixture of the cell in it.
SimWorld::Scene& SimWorld::scene(const std::string& name) {
  auto [it, created] = scenes_.try_emplace(name);
  if (created) {
    it->second.world = std::make_unique<CollisionWorld>(options_);
    for (auto& [id, b] : bodies_) {
      if (b.spec.fixture && b.spec.is_static) add_obstacle(b, name);
    }
  }
  return it->second;
}

SimWorld::Body& SimWorld::body(const std::string& id) {
  const auto it = bodies_.find(id);
  if (it == bodies_.end()) throw SimError("no body " + id);
  return it->second;
}

void SimWorld::spawn(const BodySpec& spec) {
  if (spec.id.empty()) throw SimError("a body needs an id");
  if (bodies_.count(spec.id)) throw SimError("body " + spec.id + " exists already");
  if (spec.fixture && !(spec.is_static && spec.scene.empty())) {
    throw SimError("fixture " + spec.id + " must be static and in the physical cell");
  }
  Body body{spec, nullptr, {}};
  if (!spec.mesh_uri.empty()) {
    try {
      body.mesh = meshes_.get(spec.mesh_uri, spec.mesh_scale);
    } catch (const MeshError& e) {
      throw SimError("body " + spec.id + ": " + e.what());
    }
  }
  ++scene(spec.scene).bodies;
  if (spec.is_static) add_obstacle(body);
  bodies_.emplace(spec.id, std::move(body));
}

void SimWorld::add_obstacle(Body& body) {
  add_obstacle(body, body.spec.scene);
  if (body.spec.fixture) {
    for (const auto& [name, s] : scenes_) {
      if (!name.empty()) add_obstacle(body, name);
    }
  }
}

void SimWorld::add_obstacle(Body& body, const std::string& scene_name) {
  CollisionWorld& world = *scene(scene_name).world;
  if (body.mesh) {
    body.obstacle[scene_name] = world.add_static_mesh(body.spec.id, body.mesh, body.spec.pose);
  } else if (!body.spec.half_extents.isZero()) {
    body.obstacle[scene_name] = world.add_static_box(body.spec.id, body.spec.half_extents, body.spec.pose);
  }
}

void SimWorld::remove_obstacle(Body& body) {
  for (const auto& [name, id] : body.obstacle) scenes_.at(name).world->remove(id);
  body.obstacle.clear();
}

void SimWorld::remove(const std::string& id) {
  Body& b = body(id);
  remove_obstacle(b);
  const std::string scene_name = b.spec.scene;
  bodies_.erase(id);
  // A virtual scene goes with its last body.
  if (--scenes_.at(scene_name).bodies == 0 && !scene_name.empty()) scenes_.erase(scene_name);
}

void SimWorld::set_static(const std::string& id, bool is_static) {
  Body& b = body(id);
  if (b.spec.is_static == is_static) return;
  b.spec.is_static = is_static;
  if (is_static) {
    add_obstacle(b);
  } else {
    remove_obstacle(b);
  }
}

MoveResult SimWorld::move(const MoveRequest& request) {
  if (request.speed <= 0) throw SimError("a move of " + request.body + " needs a speed above 0");
  std::vector<Body*> moving{&body(request.body)};
  for (const auto& id : request.carried) moving.push_back(&body(id));
  for (const Body* b : moving) {
    if (b->spec.is_static) throw SimError("body " + b->spec.id + " is static: set it movable before moving it");
    if (b->spec.scene != moving.front()->spec.scene) {
      throw SimError("body " + b->spec.id + " is in another scene than " + request.body);
    }
  }
  const std::string& scene = moving.front()->spec.scene;
  const CollisionWorld& world = *scenes_.at(scene).world;
  // A body turned into a thread may go into the thread's body (`ignore`); the others, moved
  // as `others`, may not.
  BodyId ignore = -1;
  if (!request.turning.empty()) {
    if (std::find(request.carried.begin(), request.carried.end(), request.turning) == request.carried.end()) {
      throw SimError("turning: " + request.turning + " is not carried by the move");
    }
    const Body& into = body(request.into);
    const auto obstacle = into.obstacle.find(scene);
    if (obstacle == into.obstacle.end()) throw SimError("into: " + request.into + " is no obstacle in the move's scene");
    ignore = obstacle->second;
  }
  // One compound in the frame of the moving body, each member at its offset now.
  const Pose start = moving.front()->spec.pose;
  MovingBody compound, others;
  const double margin = options_.shape_margin;
  std::vector<Pose> offsets;
  for (const Body* b : moving) {
    const Pose offset = offsets.emplace_back(start.inverse() * b->spec.pose);
    for (MovingBody* into : {&compound, &others}) {
      if (into == &others && (ignore < 0 || b->spec.id == request.turning)) continue;
      if (b->mesh) {
        into->add_mesh(b->spec.id, b->mesh, offset, margin);
      } else if (!b->spec.half_extents.isZero()) {
        into->add_box(b->spec.id, b->spec.half_extents, offset, margin);
      }
    }
  }

  MoveResult result;
  Pose at = start;
  for (const Pose& next : request.path) {
    const double length = (next.translation() - at.translation()).norm();
    const double duration = segment_duration(at, next, request.speed, request.angular_speed);
    std::optional<Contact> contact;
    if (!compound.empty()) contact = world.sweep(compound, at, next, ignore);
    if (!contact && !others.empty()) contact = world.sweep(others, at, next);
    const double done = contact ? contact->fraction : 1.0;
    result.distance += done * length;
    result.duration += done * duration;
    const Pose reached = interpolate(at, next, done);
    if (contact) {
      result.collided = true;
      result.hit_body = contact->body_name;
      result.hit_member = contact->member;
      result.depth = contact->depth;
    }
    at = reached;
    if (contact) break;
  }
  for (std::size_t i = 0; i < moving.size(); ++i) moving[i]->spec.pose = at * offsets[i];
  return result;
}

std::optional<Pose> SimWorld::pose(const std::string& id) const {
  const auto it = bodies_.find(id);
  if (it == bodies_.end()) return std::nullopt;
  return it->second.spec.pose;
}

std::string SimWorld::scene_of(const std::string& id) const {
  const auto it = bodies_.find(id);
  return it == bodies_.end() ? std::string() : it->second.spec.scene;
}

bool SimWorld::is_fixture(const std::string& id) const {
  const auto it = bodies_.find(id);
  return it != bodies_.end() && it->second.spec.fixture;
}

bool SimWorld::is_static(const std::string& id) const {
  const auto it = bodies_.find(id);
  return it != bodies_.end() && it->second.spec.is_static;
}

}  // namespace sim
