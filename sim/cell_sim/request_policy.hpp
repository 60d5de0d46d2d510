#pragma once
// What cell-sim accepts: a request well formed (finite numbers, unit quaternions, positions
// inside the cell, sizes not negative, speeds above 0, a mesh file that exists and is not
// huge, texts and lists within their limits) and allowed. A body belongs to whoever spawned
// it: a twin's parts to its order, a gripper to its arm. Its owner may change it; so may a
// resource acting for the owning order (the request's order_id) while that order has hired
// it (an award it confirmed). The cell's fixtures (the stations' tables) no one changes.
// A virtual scene is its order's alone.
//
// Requesters name themselves: this keeps well-behaved processes from each other's bodies and
// refuses a stranger; proving who a requester is, is DDS-Security's part (docs/topics.md).

#include <map>
#include <set>
#include <string>
#include <vector>

#include "services/blocks/sample_checks.hpp"
#include "sim/world/sim_world.hpp"

namespace sim {

class RequestPolicy {
 public:
  explicit RequestPolicy(fb::CellBounds bounds = {}) : bounds_(bounds) {}

  // "" when the request may go ahead; otherwise why not, naming the field or the body.
  std::string problem_with(const fb::Data& request, const SimWorld& world) const;

  void hired(const std::string& resource, const std::string& order) { hired_[resource].insert(order); }
  // A resource of the cell has bodies of its own in the world (a table, a gripper, a base).
  bool has_bodies(const std::string& requester) const {
    for (const auto& [body, owner] : owner_) {
      if (owner == requester) return true;
    }
    return false;
  }
  bool hired_by(const std::string& resource, const std::string& order) const {
    const auto it = hired_.find(resource);
    return it != hired_.end() && it->second.count(order);
  }
  void spawned(const std::string& body, const std::string& requester) { owner_[body] = requester; }
  void removed(const std::string& body) { owner_.erase(body); }
  // Who spawned the body ("" when no one did).
  std::string owner_of(const std::string& body) const {
    const auto it = owner_.find(body);
    return it == owner_.end() ? "" : it->second;
  }
  // The order is over: it hires no one any more; returns the bodies it owned, now forgotten.
  std::vector<std::string> order_ended(const std::string& order);

 private:
  std::string well_formed(const fb::Data& request) const;
  std::string may_change(const std::string& body, const fb::Data& request, const SimWorld& world) const;

  fb::CellBounds bounds_;
  std::map<std::string, std::string> owner_;             // body -> the requester that spawned it
  std::map<std::string, std::set<std::string>> hired_;   // resource -> orders it confirmed awards to
};

}  // namespace sim
