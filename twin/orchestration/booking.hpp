#pragma once
// An order's bookings in the cell's contract net (docs/negotiation.md): the calls it makes
// and what came back. A station to host the order (the one call that may end in a queue);
// once the station is the order's, that station's arm, a buffer for each part type (with the
// count), and a mobile robot for the batch of fetches in planned order, called once every
// buffer is known (its bid depends on where it fetches from). An order for a quote makes the
// same calls as calls for quotes (ASK): the answers are the best bids, nothing awarded. This
// builds the calls and keeps the answers; the orchestrator's chart decides when to call, and
// sends them.

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "services/runtime/event.hpp"

namespace twin {

class Booking {
 public:
  explicit Booking(std::string order_id) : order_(std::move(order_id)) {}

  // The calls' data (for CALL or ASK). `only`: call that station alone ("": any); `hold`:
  // how long the order would hold a station (s).
  fb::Data host(const std::string& only, double hold) const;
  fb::Data arm(double hold) const;  // the awarded station's
  // `fetched`: the type of each part a step fetches, in planned order (the plan may change
  // in virtual assembly, so it is given at each call).
  std::vector<fb::Data> gives(const std::vector<std::string>& fetched) const;  // per type, for the station chosen
  // The robot's call, once a station is chosen and a buffer of every type is known; once.
  std::optional<fb::Data> robot_when_ready(const std::vector<std::string>& fetched);

  // An award (AWARDED: the resource is the order's, to release at the end) or a best bid
  // (QUOTED: nothing awarded); recorded, and what it was for.
  enum class For { host, arm, robot, give };
  For awarded(const fb::Data& award);
  For quoted(const fb::Data& best);
  // The order leaves its station's queue to book again: its award there is dropped.
  void leave_station();
  // How long the bidder's queue holds the work up, from a QUOTED (its own clock).
  static double queue_of(const fb::Data& quoted);
  // The id of the order's call for a buffer of `type`: a fetch names the award it draws on.
  static std::string give_call_id(const std::string& order, const std::string& type);

  const std::string& station() const { return station_; }
  const std::string& arm_resource() const { return arm_; }
  const std::string& robot() const { return robot_; }
  const std::map<std::string, std::string>& buffer_of() const { return buffer_of_; }  // part type -> buffer
  const std::set<std::string>& to_release() const { return awarded_; }
  // The call `resource` was awarded by ("": none): commands name it.
  std::string award_of(const std::string& resource) const;
  bool holds(const std::string& resource) const { return awarded_.count(resource) > 0; }

 private:
  fb::Data call(const std::string& what, const std::string& operation, const std::string& type, long count,
                double duration, const std::string& station, const std::string& sources = "") const;

  std::string order_;
  std::string station_, arm_, robot_;
  std::map<std::string, std::string> buffer_of_;
  std::set<std::string> awarded_;
  std::map<std::string, std::string> award_of_;
  bool robot_called_ = false;
};

}  // namespace twin
