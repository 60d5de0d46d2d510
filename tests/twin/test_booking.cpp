// An order's bookings (twin/orchestration/booking): the calls it makes and what it keeps of
// the answers, without the negotiation.

#include <catch2/catch.hpp>

#include "twin/orchestration/booking.hpp"

namespace {

using fb::Data;
using fb::get;

Data answer(const std::string& call, const std::string& resource) {
  return {{"call_id", "o1/" + call}, {"resource_id", resource}, {"ahead", std::int64_t(0)}};
}

}  // namespace

TEST_CASE("booking: a station, then its arm, a buffer per type, and a robot once every buffer is known", "[twin][booking]") {
  twin::Booking b("o1");
  const std::vector<std::string> fetched{"Peg", "Plate", "Peg"};
  const Data host = b.host("", 12.5);
  CHECK(get<std::string>(host, "call_id") == "o1/host");
  CHECK(get<double>(host, "duration") == 12.5);
  CHECK(get<std::string>(host, "station").empty());
  CHECK(b.awarded(answer("host", "station-2")) == twin::Booking::For::host);
  CHECK(b.station() == "station-2");
  CHECK(get<std::string>(b.arm(9), "station") == "station-2");

  const auto gives = b.gives(fetched);
  REQUIRE(gives.size() == 2);
  CHECK(get<std::string>(gives[0], "part_type") == "Peg");
  CHECK(get<std::int64_t>(gives[0], "count") == 2);
  CHECK(get<std::string>(gives[1], "call_id") == "o1/give/Plate");
  CHECK_FALSE(b.robot_when_ready(fetched));  // no buffer known yet
  CHECK(b.awarded(answer("give/Peg", "rack-a")) == twin::Booking::For::give);
  CHECK_FALSE(b.robot_when_ready(fetched));
  CHECK(b.awarded(answer("give/Plate", "rack-b")) == twin::Booking::For::give);
  const auto robot = b.robot_when_ready(fetched);
  REQUIRE(robot);
  CHECK(get<std::string>(*robot, "sources") == "rack-a,rack-b,rack-a");  // the fetches in planned order
  CHECK(get<std::int64_t>(*robot, "count") == 3);
  CHECK_FALSE(b.robot_when_ready(fetched));  // once
  CHECK(b.awarded(answer("robot", "robot-1")) == twin::Booking::For::robot);
  CHECK(b.awarded(answer("arm", "arm-2")) == twin::Booking::For::arm);
  CHECK(b.award_of("arm-2") == "o1/arm");
  CHECK(b.to_release() == std::set<std::string>{"station-2", "rack-a", "rack-b", "robot-1", "arm-2"});

  // Leaving the station's queue drops its award, not the others.
  b.leave_station();
  CHECK_FALSE(b.holds("station-2"));
  CHECK(b.award_of("station-2").empty());
  CHECK(b.holds("arm-2"));
}

TEST_CASE("booking: a quote's best bids are kept, nothing is held, and a queue is read on the bidder's clock", "[twin][booking]") {
  twin::Booking b("o1");
  Data best = answer("host", "station-1");
  best["earliest_start"] = 130.0;
  best["bid_time"] = 100.0;
  CHECK(b.quoted(best) == twin::Booking::For::host);
  CHECK(b.station() == "station-1");
  CHECK(b.to_release().empty());
  CHECK(twin::Booking::queue_of(best) == 30);
  best["earliest_start"] = 99.0;  // a bidder whose clock runs behind the twin's: no negative wait
  CHECK(twin::Booking::queue_of(best) == 0);
}
