#pragma once
// Building cell-sim requests as event data, for device blocks that move things. Each request
// gets an id of its requester's, so the device knows its reply among everyone's.

#include <string>
#include <vector>

#include "services/runtime/event.hpp"

namespace fb {

class SimRequests {
 public:
  explicit SimRequests(std::string requester) : requester_(std::move(requester)) {}

  // The order the next requests are made for (a hired resource moving its parts); "" for the
  // requester's own bodies. cell-sim lets a resource change an order's bodies only while the
  // order has hired it.
  void act_for(const std::string& order) { order_ = order; }

  // `scene`: where the body lives ("" the physical cell, else a virtual scene).
  Data spawn(const std::string& body, const Numbers& placement, const Numbers& half_extents, bool is_static,
             const std::string& mesh_uri = "", const std::string& scene = "", double mesh_scale = 1);
  // A static body of the cell that every scene sees (a station's table).
  Data spawn_fixture(const std::string& body, const Numbers& placement, const Numbers& half_extents);
  Data remove(const std::string& body);
  Data ping();
  Data set_static(const std::string& body, bool is_static);
  // `turning`, `into`: a carried body turned into the thread of another (SimRequest).
  Data move(const std::string& body, const std::vector<std::string>& carried, const Numbers& path, double speed,
            double angular_speed, const std::string& turning = "", const std::string& into = "");

  // Whether a SIM_REPLY answers the last request made.
  bool answers_last(const Data& reply) const;
  const std::string& last() const { return last_; }

 private:
  Data request(const std::string& kind, const std::string& body);
  std::string requester_;
  std::string last_;
  std::string order_;
  std::size_t count_ = 0;
};

}  // namespace fb

namespace fb {

// A move's reply as what a device reports: DONE data (sim_time, distance, duration), or, in
// `failure`, why it failed ("collision of arm-1/palm with B6, 1.2 mm deep").
Data move_outcome(const Data& reply, std::string& failure);

}  // namespace fb
