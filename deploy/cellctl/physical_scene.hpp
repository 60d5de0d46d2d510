#pragma once
// The physical cell as cell-sim's requests and replies tell it, for the dashboard's 3D view:
// every body spawned in the physical scene (the stations' tables, the arms' grippers, the
// mobile robots' bases, the parts), where it is, and the move it is making. A move is taken
// when its request is heard: it starts at that sim time and runs through its path at
// cell-sim's pace (sim::segment_duration); its reply, at its end, sets when it really began
// and where a collision stopped it, or undoes it when cell-sim refused it. Bodies of virtual
// scenes (the twins' virtual assembly) are not followed.
//
// Requests are events: a spawn made before this reader matched its writer is never heard (a
// resource spawns its own bodies as it starts). A move by a resource of the cell of a body
// never heard spawned takes the body in where the move begins, shapeless.
//
// Requests come from the network: a body past kMaxBodies, a pose that is not finite, a move
// of a body never spawned here are ignored. Thread-safe: DDS threads feed it, the
// dashboard's feed reads it.

#include <cstddef>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "simulation.h"

namespace cellctl {

class PhysicalScene {
 public:
  // `resources`: the cell's resource ids, the requesters whose moves of unknown bodies count.
  explicit PhysicalScene(std::set<std::string> resources = {}) : resources_(std::move(resources)) {}

  static constexpr std::size_t kMaxBodies = 5000;
  static constexpr std::size_t kMaxMovesUnanswered = 4096;

  // `sim_now`: the cell's sim time when the request was heard. Both: whether the scene changed.
  bool take(const cell::SimRequest& request, double sim_now);
  bool take(const cell::SimReply& reply);

  // Every body: {id, owner (the resource whose own body it is; "" for an order's), order (the
  // order whose part it is: a mesh its twin spawned), half_extents, mesh (whether it is a
  // mesh's), pose [x, y, z, qw, qx, qy, qz], and while it
  // moves at `sim_now`, motion {t: [sim s], poses: [pose]}: at t[i] it is at poses[i]}.
  nlohmann::json bodies(double sim_now) const;
  std::size_t size() const;

 private:
  struct Motion {
    std::vector<double> times;
    std::vector<Eigen::Isometry3d> poses;
  };
  struct Body {
    std::string owner;
    std::string order;
    Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();
    bool mesh = false;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    Eigen::Isometry3d before = Eigen::Isometry3d::Identity();  // where the move began
    Motion motion;
  };
  bool spawn(const cell::SimRequest& request);
  bool move(const cell::SimRequest& request, double sim_now);

  const std::set<std::string> resources_;
  mutable std::mutex mutex_;
  std::map<std::string, Body> bodies_;
  std::map<std::string, std::vector<std::string>> moving_;  // request id -> the bodies its move took
};

}  // namespace cellctl
