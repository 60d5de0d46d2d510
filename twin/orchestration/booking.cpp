#include "twin/orchestration/booking.hpp"

#include <algorithm>

namespace twin {
namespace {

using fb::Data;
using fb::get;

const std::string kHost = "host", kArm = "arm", kRobot = "robot", kGive = "give/";

}  // namespace

Data Booking::call(const std::string& what, const std::string& operation, const std::string& type, long count,
                   double duration, const std::string& station, const std::string& sources) const {
  return {{"call_id", order_ + "/" + what}, {"operation", operation}, {"part_type", type},
          {"station", station}, {"sources", sources}, {"count", std::int64_t(count)}, {"duration", duration}};
}

std::string Booking::give_call_id(const std::string& order, const std::string& type) { return order + "/" + kGive + type; }

Data Booking::host(const std::string& only, double hold) const { return call(kHost, kHost, "", 0, hold, only); }

Data Booking::arm(double hold) const { return call(kArm, "translate", "", 0, hold, station_); }

std::vector<Data> Booking::gives(const std::vector<std::string>& fetched) const {
  std::map<std::string, long> count_of;
  for (const auto& type : fetched) ++count_of[type];
  std::vector<Data> out;
  for (const auto& [type, count] : count_of) out.push_back(call(kGive + type, "give", type, count, 0, station_));
  return out;
}

std::optional<Data> Booking::robot_when_ready(const std::vector<std::string>& fetched) {
  if (robot_called_ || station_.empty()) return std::nullopt;
  std::vector<std::string> sources;
  for (const auto& type : fetched) {
    const auto buffer = buffer_of_.find(type);
    if (buffer == buffer_of_.end()) return std::nullopt;  // not every buffer known yet
    sources.push_back(buffer->second);
  }
  robot_called_ = true;
  return call(kRobot, "fetch", "", static_cast<long>(sources.size()), 0, station_, fb::join_names(sources));
}

Booking::For Booking::quoted(const Data& best) {
  const std::string what = get<std::string>(best, "call_id").substr(order_.size() + 1);
  const std::string& resource = get<std::string>(best, "resource_id");
  if (what == kHost) {
    station_ = resource;
    return For::host;
  }
  if (what == kArm) {
    arm_ = resource;
    return For::arm;
  }
  if (what == kRobot) {
    robot_ = resource;
    return For::robot;
  }
  buffer_of_[what.substr(kGive.size())] = resource;
  return For::give;
}

Booking::For Booking::awarded(const Data& award) {
  awarded_.insert(get<std::string>(award, "resource_id"));
  award_of_[get<std::string>(award, "resource_id")] = get<std::string>(award, "call_id");
  return quoted(award);
}

void Booking::leave_station() {
  awarded_.erase(station_);
  award_of_.erase(station_);
}

double Booking::queue_of(const Data& quoted) {
  return std::max(0.0, get<double>(quoted, "earliest_start") - get<double>(quoted, "bid_time"));
}

std::string Booking::award_of(const std::string& resource) const {
  const auto it = award_of_.find(resource);
  return it == award_of_.end() ? "" : it->second;
}

}  // namespace twin
