#pragma once
// The cell's one shared world, as cell-sim keeps it: named bodies (parts, the station's
// table, the gripper, the mobile robot) with shapes and poses, some of them static
// obstacles, and motions of one body with the bodies it carries along a path, in simulated
// time from speeds, stopped at the first collision with a static body. No DDS here: the
// cell-sim process serves this over topics.
//
// Bodies live in scenes: "" is the physical cell; any other name is a virtual scene (an
// order's virtual assembly) whose moves meet only that scene's static bodies and the cell's
// fixtures (static bodies of the physical cell spawned as fixtures: the stations' tables).
// So many orders assemble virtually at once, at the same station, without meeting each
// other or the parts that stand on the station for real.

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/collision/collision_world.hpp"

namespace sim {

class SimError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct BodySpec {
  std::string id;
  std::string mesh_uri;                                         // a mesh file, or
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();       // a box; neither: no shape
  Pose pose = Pose::Identity();
  bool is_static = false;
  std::string scene;     // "" the physical cell
  bool fixture = false;  // static, in the physical cell, and seen from every scene
  double mesh_scale = 1;  // metres per unit of the mesh file
};

struct MoveRequest {
  std::string body;
  std::vector<std::string> carried;  // keep their offsets to `body` while it moves
  std::vector<Pose> path;            // poses of `body`, after its current one
  double speed = 0;                  // m/s, > 0
  double angular_speed = 0;          // rad/s; 0: turning takes no time
  // A carried body turned into the thread of `into` (a nut onto its bolt): it may go into that
  // body (the thread's overlap); the other moving bodies may not. Empty: none.
  std::string turning, into;
};

struct MoveResult {
  bool collided = false;
  std::string hit_body;    // the static body hit
  std::string hit_member;  // which moving body hit it
  double depth = 0;        // m
  double duration = 0;     // sim s, until the end or the collision
  double distance = 0;     // m travelled by `body`
};

class SimWorld {
 public:
  explicit SimWorld(CollisionOptions options = {});

  // Each throws SimError with the reason: an id taken or unknown, a mesh that cannot be read,
  // a move of a static body, a move that carries a body of another scene.
  void spawn(const BodySpec& body);
  void remove(const std::string& id);
  void set_static(const std::string& id, bool is_static);
  // Moves the bodies to the path's end, or to where they first collided.
  MoveResult move(const MoveRequest& request);

  std::optional<Pose> pose(const std::string& id) const;
  // The scene a body lives in ("" the physical cell, or when there is no such body).
  std::string scene_of(const std::string& id) const;
  bool is_static(const std::string& id) const;
  bool is_fixture(const std::string& id) const;
  std::size_t size() const { return bodies_.size(); }
  std::size_t scenes() const { return scenes_.size(); }  // the physical cell and virtual ones with bodies

 private:
  struct Body {
    BodySpec spec;
    std::shared_ptr<const TriangleMesh> mesh;
    std::map<std::string, BodyId> obstacle;  // scene -> its id in that scene's collision world, while static
  };
  struct Scene {
    std::unique_ptr<CollisionWorld> world;
    std::size_t bodies = 0;
  };
  Body& body(const std::string& id);
  Scene& scene(const std::string& name);
  void add_obstacle(Body& body);
  void add_obstacle(Body& body, const std::string& scene);
  void remove_obstacle(Body& body);

  CollisionOptions options_;
  MeshCache meshes_;
  std::map<std::string, Scene> scenes_;
  std::map<std::string, Body> bodies_;
};

}  // namespace sim
