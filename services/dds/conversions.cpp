#include "services/dds/conversions.hpp"

#include <stdexcept>

namespace dds {
namespace {
// A text field of event data, "" when missing.
std::string text(const fb::Data& d, const char* key) { return fb::get_or<std::string>(d, key, ""); }
}  // namespace

fb::Numbers to_numbers(const std::vector<cell::Pose>& path) {
  fb::Numbers out;
  for (const auto& p : path) {
    out.insert(out.end(), {p.position().x(), p.position().y(), p.position().z(), p.qw(), p.qx(), p.qy(), p.qz()});
  }
  return out;
}

std::vector<cell::Pose> to_path(const fb::Numbers& n) {
  if (n.size() % 7 != 0) throw std::invalid_argument("a path needs seven numbers per pose, got " + std::to_string(n.size()));
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
  }
  return "unknown";
}

cell::CommandEvent to_command_event(const fb::Data& d) {
  cell::CommandEvent e;
  e.command_id(text(d, "command_id"));
  e.resource_id(text(d, "resource_id"));
  e.order_id(text(d, "order_id"));
  e.operation(text(d, "operation"));
  e.part(text(d, "part"));
  const std::string state = text(d, "state");
  bool known = false;
  for (auto s : {cell::ACCEPTED, cell::EXECUTING, cell::CANCELING, cell::SUCCEEDED, cell::CANCELED, cell::ABORTED}) {
    if (state == state_name(s)) e.state(s), known = true;
  }
  if (!known) throw std::invalid_argument("no command state '" + state + "'");
  e.progress(e.state() == cell::SUCCEEDED ? 1.0 : 0.0);
  e.reason(text(d, "reason"));
  e.sim_time(fb::get_or<double>(d, "sim_time", 0));
  e.distance(fb::get_or<double>(d, "distance", 0));
  e.duration(fb::get_or<double>(d, "duration", 0));
  return e;
}

fb::Data to_data(const cell::Command& c) {
  return {{"command_id", c.command_id()},   {"resource_id", c.resource_id()}, {"order_id", c.order_id()},
          {"operation", c.operation()},     {"part", c.part()},               {"part_type", c.part_type()},
          {"source", c.source()},           {"destination", c.destination()}, {"path", to_numbers(c.path())},
          {"size", to_numbers(c.size())},   {"direction", to_numbers(c.direction())},
          {"sim_time", c.sim_time()}};
}

cell::Command to_command(const fb::Data& d) {
  cell::Command c;
  c.command_id(text(d, "command_id"));
  c.resource_id(text(d, "resource_id"));
  c.order_id(text(d, "order_id"));
  c.operation(text(d, "operation"));
  c.part(text(d, "part"));
  c.part_type(text(d, "part_type"));
  c.source(text(d, "source"));
  c.destination(text(d, "destination"));
  c.path(to_path(fb::get_or<fb::Numbers>(d, "path", {})));
  c.size(to_vec3(fb::get_or<fb::Numbers>(d, "size", {0, 0, 0})));
  c.direction(to_vec3(fb::get_or<fb::Numbers>(d, "direction", {0, 0, 0})));
  c.sim_time(fb::get_or<double>(d, "sim_time", 0));
  return c;
}

fb::Data to_data(const cell::SimReply& r) {
  return {{"request_id", r.request_id()}, {"requester", r.requester()}, {"ok", r.ok()}, {"error", r.error()},
          {"collided", r.collided()},     {"hit_body", r.hit_body()}, {"hit_member", r.hit_member()},
          {"depth", r.depth()},           {"start_time", r.start_time()}, {"end_time", r.end_time()},
          {"distance", r.distance()}};
}

cell::SimRequest to_sim_request(const fb::Data& d) {
  cell::SimRequest r;
  r.request_id(text(d, "request_id"));
  r.requester(text(d, "requester"));
  r.kind(text(d, "kind"));
  r.body_id(text(d, "body_id"));
  r.scene(text(d, "scene"));
  r.fixture(fb::get_or<bool>(d, "fixture", false));
  r.mesh_uri(text(d, "mesh_uri"));
  r.half_extents(to_vec3(fb::get_or<fb::Numbers>(d, "half_extents", {0, 0, 0})));
  const auto placement = to_path(fb::get_or<fb::Numbers>(d, "placement", {0, 0, 0, 1, 0, 0, 0}));
  if (placement.size() != 1) throw std::invalid_argument("a placement is one pose");
  r.placement(placement.front());
  r.is_static(fb::get_or<bool>(d, "is_static", false));
  r.carried(fb::split_names(text(d, "carried")));
  r.path(to_path(fb::get_or<fb::Numbers>(d, "path", {})));
  r.speed(fb::get_or<double>(d, "speed", 0));
  r.angular_speed(fb::get_or<double>(d, "angular_speed", 0));
  return r;
}

}  // namespace dds

namespace dds {

fb::Data to_data(const cell::SimRequest& r) {
  return {{"request_id", r.request_id()},
          {"requester", r.requester()},
          {"kind", r.kind()},
          {"body_id", r.body_id()},
          {"scene", r.scene()},
          {"fixture", r.fixture()},
          {"mesh_uri", r.mesh_uri()},
          {"half_extents", to_numbers(r.half_extents())},
          {"placement", to_numbers(std::vector<cell::Pose>{r.placement()})},
          {"is_static", r.is_static()},
          {"carried", fb::join_names(r.carried())},
          {"path", to_numbers(r.path())},
          {"speed", r.speed()},
          {"angular_speed", r.angular_speed()}};
}

cell::SimReply to_sim_reply(const fb::Data& d) {
  cell::SimReply r;
  r.request_id(fb::get<std::string>(d, "request_id"));
  r.requester(fb::get_or<std::string>(d, "requester", ""));
  r.ok(fb::get_or<bool>(d, "ok", false));
  r.error(fb::get_or<std::string>(d, "error", ""));
  r.collided(fb::get_or<bool>(d, "collided", false));
  r.hit_body(fb::get_or<std::string>(d, "hit_body", ""));
  r.hit_member(fb::get_or<std::string>(d, "hit_member", ""));
  r.depth(fb::get_or<double>(d, "depth", 0));
  r.start_time(fb::get_or<double>(d, "start_time", 0));
  r.end_time(fb::get_or<double>(d, "end_time", 0));
  r.distance(fb::get_or<double>(d, "distance", 0));
  return r;
}

}  // namespace dds

namespace dds {

fb::Data to_data(const cell::CallForProposals& c) {
  return {{"call_id", c.call_id()},     {"order_id", c.order_id()}, {"operation", c.operation()},
          {"part_type", c.part_type()}, {"count", std::int64_t(c.count())}, {"station", c.station()},
          {"sources", fb::join_names(c.sources())}, {"duration", c.duration()}};
}

cell::CallForProposals to_call(const fb::Data& d) {
  cell::CallForProposals c;
  c.call_id(text(d, "call_id"));
  c.order_id(text(d, "order_id"));
  c.operation(text(d, "operation"));
  c.part_type(text(d, "part_type"));
  c.count(static_cast<int32_t>(fb::get_or<std::int64_t>(d, "count", 0)));
  c.station(text(d, "station"));
  c.sources(fb::split_names(text(d, "sources")));
  c.duration(fb::get_or<double>(d, "duration", 0));
  return c;
}

fb::Data to_data(const cell::Proposal& p) {
  return {{"call_id", p.call_id()},   {"resource_id", p.resource_id()}, {"available", p.available()},
          {"reason", p.reason()},     {"earliest_start", p.earliest_start()}, {"duration", p.duration()}};
}

cell::Proposal to_proposal(const fb::Data& d) {
  cell::Proposal p;
  p.call_id(text(d, "call_id"));
  p.resource_id(text(d, "resource_id"));
  p.available(fb::get_or<bool>(d, "available", false));
  p.reason(text(d, "reason"));
  p.earliest_start(fb::get_or<double>(d, "earliest_start", 0));
  p.duration(fb::get_or<double>(d, "duration", 0));
  return p;
}

fb::Data to_data(const cell::Award& a) {
  return {{"call_id", a.call_id()}, {"resource_id", a.resource_id()}, {"order_id", a.order_id()}, {"lease", a.lease()}};
}

cell::Award to_award(const fb::Data& d) {
  cell::Award a;
  a.call_id(text(d, "call_id"));
  a.resource_id(text(d, "resource_id"));
  a.order_id(text(d, "order_id"));
  a.lease(fb::get_or<double>(d, "lease", 0));
  return a;
}

fb::Data to_data(const cell::AwardReply& r) {
  return {{"call_id", r.call_id()}, {"resource_id", r.resource_id()}, {"confirmed", r.confirmed()},
          {"reason", r.reason()},   {"ahead", std::int64_t(r.ahead())}};
}

cell::AwardReply to_award_reply(const fb::Data& d) {
  cell::AwardReply r;
  r.call_id(text(d, "call_id"));
  r.resource_id(text(d, "resource_id"));
  r.confirmed(fb::get_or<bool>(d, "confirmed", false));
  r.reason(text(d, "reason"));
  r.ahead(static_cast<int32_t>(fb::get_or<std::int64_t>(d, "ahead", 0)));
  return r;
}

fb::Data to_data(const cell::Release& r) { return {{"order_id", r.order_id()}, {"resource_id", r.resource_id()}}; }

cell::Release to_release(const fb::Data& d) {
  cell::Release r;
  r.order_id(text(d, "order_id"));
  r.resource_id(text(d, "resource_id"));
  return r;
}

fb::Data to_data(const cell::Capability& c) {
  return {{"resource_id", c.resource_id()},
          {"kind", c.kind()},
          {"operations", fb::join_names(c.operations())},
          {"position", to_numbers(c.position())},
          {"dock", to_numbers(c.dock())},
          {"speed", c.speed()},
          {"angular_speed", c.angular_speed()},
          {"reserved_by", c.reserved_by()},
          {"waiting", fb::join_names(c.waiting())},
          {"queued_commands", std::int64_t(c.queued_commands())},
          {"busy", c.busy()}};
}

}  // namespace dds
