#include "services/dds/conversions.hpp"

#include <stdexcept>

namespace dds {
namespace {
// A text field of event data, "" when missing.
std::string text(const fb::Data& d, const char* key) { return fb::get_or<std::string>(d, key, ""); }

// The IDL's bounded strings cut what is longer (eprosima::fastrtps::fixed_string): never
// send a field cut short, refuse it.
template <class Bounded>
Bounded bounded(const fb::Data& d, const char* key) {
  const std::string value = text(d, key);
  if (value.size() >= Bounded::max_size) {
    throw std::length_error(std::string(key) + " is " + std::to_string(value.size()) + " characters, more than " +
                            std::to_string(Bounded::max_size - 1));
  }
  return Bounded(value);
}
cell::Id id(const fb::Data& d, const char* key) { return bounded<cell::Id>(d, key); }
cell::Text message(const fb::Data& d, const char* key) { return bounded<cell::Text>(d, key); }
cell::FilePath path_text(const fb::Data& d, const char* key) { return bounded<cell::FilePath>(d, key); }

cell::Ids ids(const fb::Data& d, const char* key) {
  cell::Ids out;
  for (const std::string& name : fb::split_names(text(d, key))) {
    if (name.size() >= cell::Id::max_size) throw std::length_error(std::string("a name in ") + key + " is too long");
    out.emplace_back(name);
  }
  return out;
}
}  // namespace

std::string names(const cell::Ids& ids) {
  std::vector<std::string> out;
  for (const cell::Id& id : ids) out.push_back(id.to_string());
  return fb::join_names(out);
}

fb::Numbers to_numbers(const std::vector<cell::Pose>& path) {
  fb::Numbers out;
  for (const auto& p : path) {
    out.insert(out.end(), {p.position().x(), p.position().y(), p.position().z(), p.qw(), p.qx(), p.qy(), p.qz()});
  }
  return out;
}

std::vector<cell::Pose> to_path(const fb::Numbers& n) {
  if (n.size() % 7 != 0) {
    throw std::invalid_argument("a path needs seven numbers per pose, got " + std::to_string(n.size()));
  }
  if (n.size() / 7 > static_cast<std::size_t>(cell::MAX_WAYPOINTS)) {
    throw std::length_error("a path of " + std::to_string(n.size() / 7) + " poses, more than " +
                            std::to_string(cell::MAX_WAYPOINTS));
  }
  std::vector<cell::Pose> path(n.size() / 7);
  for (std::size_t i = 0; i < path.size(); ++i) {
    const double* v = &n[7 * i];
    path[i].position(vec3(v[0], v[1], v[2]));
    path[i].qw(v[3]);
    path[i].qx(v[4]);
    path[i].qy(v[5]);
    path[i].qz(v[6]);
  }
  return path;
}

fb::Numbers to_numbers(const cell::Vec3& v) { return {v.x(), v.y(), v.z()}; }

cell::Vec3 to_vec3(const fb::Numbers& n) {
  if (n.size() != 3) throw std::invalid_argument("a vector needs three numbers, got " + std::to_string(n.size()));
  return vec3(n[0], n[1], n[2]);
}

cell::Vec3 vec3(double x, double y, double z) {
  cell::Vec3 v;
  v.x(x);
  v.y(y);
  v.z(z);
  return v;
}

}  // namespace dds

namespace dds {

const char* state_name(cell::CommandState state) {
  switch (state) {
    case cell::ACCEPTED: return "accepted";
    case cell::EXECUTING: return "executing";
    case cell::CANCELING: return "canceling";
    case cell::SUCCEEDED: return "succeeded";
    case cell::CANCELED: return "canceled";
    case cell::ABORTED: return "aborted";
    case cell::REJECTED: return "rejected";
  }
  return "unknown";
}

cell::CommandEvent to_command_event(const fb::Data& d) {
  cell::CommandEvent e;
  e.command_id(id(d, "command_id"));
  e.resource_id(id(d, "resource_id"));
  e.order_id(id(d, "order_id"));
  e.operation(id(d, "operation"));
  e.part(id(d, "part"));
  const std::string state = text(d, "state");
  bool known = false;
  for (auto s : {cell::ACCEPTED, cell::EXECUTING, cell::CANCELING, cell::SUCCEEDED, cell::CANCELED, cell::ABORTED,
                 cell::REJECTED}) {
    if (state == state_name(s)) e.state(s), known = true;
  }
  if (!known) throw std::invalid_argument("no command state '" + state + "'");
  e.progress(e.state() == cell::SUCCEEDED ? 1.0 : 0.0);
  e.reason(message(d, "reason"));
  e.sim_time(fb::get_or<double>(d, "sim_time", 0));
  e.distance(fb::get_or<double>(d, "distance", 0));
  e.duration(fb::get_or<double>(d, "duration", 0));
  return e;
}

fb::Data to_data(const cell::Command& c) {
  return {{"command_id", c.command_id().to_string()},
          {"resource_id", c.resource_id().to_string()},
          {"order_id", c.order_id().to_string()},
          {"operation", c.operation().to_string()},
          {"part", c.part().to_string()},
          {"part_type", c.part_type().to_string()},
          {"source", c.source().to_string()},
          {"destination", c.destination().to_string()},
          {"award", c.award().to_string()},
          {"source_award", c.source_award().to_string()},
          {"path", to_numbers(c.path())},
          {"opening", c.opening()},
          {"carried", names(c.carried())},
          {"turns", c.turns()},
          {"pitch", c.pitch()},
          {"sim_time", c.sim_time()}};
}

cell::Command to_command(const fb::Data& d) {
  cell::Command c;
  c.command_id(id(d, "command_id"));
  c.resource_id(id(d, "resource_id"));
  c.order_id(id(d, "order_id"));
  c.operation(id(d, "operation"));
  c.part(id(d, "part"));
  c.part_type(id(d, "part_type"));
  c.source(id(d, "source"));
  c.destination(id(d, "destination"));
  c.award(id(d, "award"));
  c.source_award(id(d, "source_award"));
  c.path(to_path(fb::get_or<fb::Numbers>(d, "path", {})));
  c.opening(fb::get_or<double>(d, "opening", 0));
  c.carried(ids(d, "carried"));
  c.turns(fb::get_or<double>(d, "turns", 0));
  c.pitch(fb::get_or<double>(d, "pitch", 0));
  c.sim_time(fb::get_or<double>(d, "sim_time", 0));
  return c;
}

fb::Data to_data(const cell::SimReply& r) {
  return {{"request_id", r.request_id().to_string()},
          {"requester", r.requester().to_string()},
          {"ok", r.ok()},
          {"error", r.error().to_string()},
          {"collided", r.collided()},
          {"hit_body", r.hit_body().to_string()},
          {"hit_member", r.hit_member().to_string()},
          {"depth", r.depth()},
          {"start_time", r.start_time()},
          {"end_time", r.end_time()},
          {"distance", r.distance()}};
}

cell::SimRequest to_sim_request(const fb::Data& d) {
  cell::SimRequest r;
  r.request_id(id(d, "request_id"));
  r.requester(id(d, "requester"));
  r.order_id(id(d, "order_id"));
  r.kind(id(d, "kind"));
  r.body_id(id(d, "body_id"));
  r.scene(id(d, "scene"));
  r.fixture(fb::get_or<bool>(d, "fixture", false));
  r.mesh_uri(path_text(d, "mesh_uri"));
  r.mesh_scale(fb::get_or<double>(d, "mesh_scale", 1));
  r.half_extents(to_vec3(fb::get_or<fb::Numbers>(d, "half_extents", {0, 0, 0})));
  const auto placement = to_path(fb::get_or<fb::Numbers>(d, "placement", {0, 0, 0, 1, 0, 0, 0}));
  if (placement.size() != 1) throw std::invalid_argument("a placement is one pose");
  r.placement(placement.front());
  r.is_static(fb::get_or<bool>(d, "is_static", false));
  r.carried(ids(d, "carried"));
  r.path(to_path(fb::get_or<fb::Numbers>(d, "path", {})));
  r.speed(fb::get_or<double>(d, "speed", 0));
  r.angular_speed(fb::get_or<double>(d, "angular_speed", 0));
  r.turning(id(d, "turning"));
  r.into(id(d, "into"));
  return r;
}

}  // namespace dds

namespace dds {

fb::Data to_data(const cell::SimRequest& r) {
  return {{"request_id", r.request_id().to_string()},
          {"requester", r.requester().to_string()},
          {"order_id", r.order_id().to_string()},
          {"kind", r.kind().to_string()},
          {"body_id", r.body_id().to_string()},
          {"scene", r.scene().to_string()},
          {"fixture", r.fixture()},
          {"mesh_uri", r.mesh_uri().to_string()},
          {"mesh_scale", r.mesh_scale()},
          {"half_extents", to_numbers(r.half_extents())},
          {"placement", to_numbers(std::vector<cell::Pose>{r.placement()})},
          {"is_static", r.is_static()},
          {"carried", names(r.carried())},
          {"path", to_numbers(r.path())},
          {"speed", r.speed()},
          {"angular_speed", r.angular_speed()},
          {"turning", r.turning().to_string()},
          {"into", r.into().to_string()}};
}

cell::SimReply to_sim_reply(const fb::Data& d) {
  cell::SimReply r;
  r.request_id(id(d, "request_id"));
  r.requester(id(d, "requester"));
  r.ok(fb::get_or<bool>(d, "ok", false));
  r.error(message(d, "error"));
  r.collided(fb::get_or<bool>(d, "collided", false));
  r.hit_body(id(d, "hit_body"));
  r.hit_member(id(d, "hit_member"));
  r.depth(fb::get_or<double>(d, "depth", 0));
  r.start_time(fb::get_or<double>(d, "start_time", 0));
  r.end_time(fb::get_or<double>(d, "end_time", 0));
  r.distance(fb::get_or<double>(d, "distance", 0));
  return r;
}

}  // namespace dds

namespace dds {

fb::Data to_data(const cell::CallForProposals& c) {
  return {{"call_id", c.call_id().to_string()},     {"order_id", c.order_id().to_string()},
          {"operation", c.operation().to_string()}, {"part_type", c.part_type().to_string()},
          {"count", std::int64_t(c.count())},       {"station", c.station().to_string()},
          {"sources", names(c.sources())},          {"duration", c.duration()}};
}

cell::CallForProposals to_call(const fb::Data& d) {
  cell::CallForProposals c;
  c.call_id(id(d, "call_id"));
  c.order_id(id(d, "order_id"));
  c.operation(id(d, "operation"));
  c.part_type(id(d, "part_type"));
  c.count(static_cast<int32_t>(fb::get_or<std::int64_t>(d, "count", 0)));
  c.station(id(d, "station"));
  c.sources(ids(d, "sources"));
  c.duration(fb::get_or<double>(d, "duration", 0));
  return c;
}

fb::Data to_data(const cell::Proposal& p) {
  return {{"call_id", p.call_id().to_string()},   {"resource_id", p.resource_id().to_string()},
          {"available", p.available()},           {"reason", p.reason().to_string()},
          {"earliest_start", p.earliest_start()}, {"duration", p.duration()}, {"bid_time", p.bid_time()}};
}

cell::Proposal to_proposal(const fb::Data& d) {
  cell::Proposal p;
  p.call_id(id(d, "call_id"));
  p.resource_id(id(d, "resource_id"));
  p.available(fb::get_or<bool>(d, "available", false));
  p.reason(message(d, "reason"));
  p.earliest_start(fb::get_or<double>(d, "earliest_start", 0));
  p.duration(fb::get_or<double>(d, "duration", 0));
  p.bid_time(fb::get_or<double>(d, "bid_time", 0));
  return p;
}

fb::Data to_data(const cell::Award& a) {
  return {{"call_id", a.call_id().to_string()},
          {"resource_id", a.resource_id().to_string()},
          {"order_id", a.order_id().to_string()},
          {"lease", a.lease()}};
}

cell::Award to_award(const fb::Data& d) {
  cell::Award a;
  a.call_id(id(d, "call_id"));
  a.resource_id(id(d, "resource_id"));
  a.order_id(id(d, "order_id"));
  a.lease(fb::get_or<double>(d, "lease", 0));
  return a;
}

fb::Data to_data(const cell::AwardReply& r) {
  return {{"call_id", r.call_id().to_string()},   {"resource_id", r.resource_id().to_string()},
          {"order_id", r.order_id().to_string()}, {"confirmed", r.confirmed()},
          {"reason", r.reason().to_string()},     {"ahead", std::int64_t(r.ahead())}};
}

cell::AwardReply to_award_reply(const fb::Data& d) {
  cell::AwardReply r;
  r.call_id(id(d, "call_id"));
  r.resource_id(id(d, "resource_id"));
  r.order_id(id(d, "order_id"));
  r.confirmed(fb::get_or<bool>(d, "confirmed", false));
  r.reason(message(d, "reason"));
  r.ahead(static_cast<int32_t>(fb::get_or<std::int64_t>(d, "ahead", 0)));
  return r;
}

fb::Data to_data(const cell::Release& r) {
  return {{"order_id", r.order_id().to_string()}, {"resource_id", r.resource_id().to_string()}};
}

cell::Release to_release(const fb::Data& d) {
  cell::Release r;
  r.order_id(id(d, "order_id"));
  r.resource_id(id(d, "resource_id"));
  return r;
}

fb::Data to_data(const cell::Capability& c) {
  return {{"resource_id", c.resource_id().to_string()},
          {"kind", c.kind().to_string()},
          {"operations", names(c.operations())},
          {"position", to_numbers(c.position())},
          {"dock", to_numbers(c.dock())},
          {"speed", c.speed()},
          {"angular_speed", c.angular_speed()},
          {"reserved_by", c.reserved_by().to_string()},
          {"waiting", names(c.waiting())},
          {"queued_commands", std::int64_t(c.queued_commands())},
          {"busy", c.busy()},
          {"refused_commands", std::int64_t(c.refused_commands())},
          {"last_refusal", c.last_refusal().to_string()},
          {"out_of_service", c.out_of_service().to_string()}};
}

}  // namespace dds
