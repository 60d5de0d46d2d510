#include "services/node/sim_requests.hpp"

namespace fb {

Data SimRequests::request(const std::string& kind, const std::string& body) {
  last_ = requester_ + "/sim/" + std::to_string(++count_);
  return {{"request_id", last_}, {"requester", requester_}, {"order_id", order_}, {"kind", kind}, {"body_id", body}};
}

Data SimRequests::spawn(const std::string& body, const Numbers& placement, const Numbers& half_extents,
                        bool is_static, const std::string& mesh_uri, const std::string& scene, double mesh_scale) {
  Data d = request("spawn", body);
  d["mesh_scale"] = mesh_scale;
  d["placement"] = placement;
  d["half_extents"] = half_extents;
  d["is_static"] = is_static;
  d["mesh_uri"] = mesh_uri;
  d["scene"] = scene;
  return d;
}

Data SimRequests::spawn_fixture(const std::string& body, const Numbers& placement, const Numbers& half_extents) {
  Data d = spawn(body, placement, half_extents, true);
  d["fixture"] = true;
  return d;
}

Data SimRequests::remove(const std::string& body) { return request("remove", body); }

Data SimRequests::ping() { return request("ping", ""); }

Data SimRequests::set_static(const std::string& body, bool is_static) {
  return request(is_static ? "set_static" : "set_movable", body);
}

Data SimRequests::move(const std::string& body, const std::vector<std::string>& carried, const Numbers& path,
                       double speed, double angular_speed, const std::string& turning, const std::string& into) {
  Data d = request("move", body);
  d["carried"] = join_names(carried);
  d["path"] = path;
  d["speed"] = speed;
  d["angular_speed"] = angular_speed;
  d["turning"] = turning;
  d["into"] = into;
  return d;
}

bool SimRequests::answers_last(const Data& reply) const { return get<std::string>(reply, "request_id") == last_; }

}  // namespace fb

namespace fb {

Data move_outcome(const Data& reply, std::string& failure) {
  failure.clear();
  const double start = get_or<double>(reply, "start_time", 0), end = get_or<double>(reply, "end_time", 0);
  Data out{{"sim_time", end}, {"distance", get_or<double>(reply, "distance", 0)}, {"duration", end - start}};
  if (!get<bool>(reply, "ok")) {
    failure = get<std::string>(reply, "error");
  } else if (get_or<bool>(reply, "collided", false)) {
    const long micrometres = static_cast<long>(get<double>(reply, "depth") * 1e6);
    failure = "collision of " + get<std::string>(reply, "hit_member") + " with " + get<std::string>(reply, "hit_body") +
              ", " + std::to_string(micrometres / 1000) + "." + std::to_string(micrometres % 1000 / 100) + " mm deep";
  }
  if (!failure.empty()) out["reason"] = failure;
  return out;
}

}  // namespace fb
