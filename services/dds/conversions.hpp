#pragma once
// Between DDS value types and event data: a pose is seven numbers (x, y, z, qw, qx, qy, qz),
// a path seven per waypoint, a list of names one comma-separated string (fb::join_names).

#include <string>
#include <vector>

#include "common.h"
#include "services/runtime/event.hpp"

namespace dds {

fb::Numbers to_numbers(const std::vector<cell::Pose>& path);
std::vector<cell::Pose> to_path(const fb::Numbers& numbers);  // throws std::invalid_argument unless 7 per pose
fb::Numbers to_numbers(const cell::Vec3& v);
cell::Vec3 to_vec3(const fb::Numbers& numbers);  // throws std::invalid_argument unless three numbers
cell::Vec3 vec3(double x, double y, double z);

}  // namespace dds

#include "commands.h"
#include "simulation.h"

namespace dds {

// Every field, by its IDL name; path, size and direction as numbers.
// "accepted", "executing", ..., as event data and the event log name them.
const char* state_name(cell::CommandState state);
fb::Data to_data(const cell::Command& command);
cell::Command to_command(const fb::Data& data);  // missing fields stay empty
fb::Data to_data(const cell::SimReply& reply);
cell::SimRequest to_sim_request(const fb::Data& data);  // carried: comma-separated body ids
fb::Data to_data(const cell::SimRequest& request);
cell::SimReply to_sim_reply(const fb::Data& data);

}  // namespace dds
