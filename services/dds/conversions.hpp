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
std::string names(const cell::Ids& ids);  // comma-separated (fb::join_names)

}  // namespace dds

#include "capabilities.h"
#include "commands.h"
#include "negotiation.h"
#include "simulation.h"

namespace dds {

// Every field, by its IDL name; path, size and direction as numbers. Towards DDS, a text
// longer than its IDL bound, or a path longer than MAX_WAYPOINTS, throws std::length_error
// (the bounded types would cut it short).
// "accepted", "executing", ..., as event data and the event log name them.
const char* state_name(cell::CommandState state);
fb::Data to_data(const cell::Command& command);
cell::Command to_command(const fb::Data& data);  // missing fields stay empty
fb::Data to_data(const cell::SimReply& reply);
cell::SimRequest to_sim_request(const fb::Data& data);  // carried: comma-separated body ids
fb::Data to_data(const cell::SimRequest& request);
cell::SimReply to_sim_reply(const fb::Data& data);
// A command's event from its command's fields and the event's (state by name, reason,
// sim_time, distance, duration); throws std::invalid_argument for an unknown state.
cell::CommandEvent to_command_event(const fb::Data& data);


// The contract net's messages, as the Contractor and Negotiator blocks take them; lists
// (a fetch batch's sources) as comma-separated names.
fb::Data to_data(const cell::CallForProposals& call);
cell::CallForProposals to_call(const fb::Data& data);
fb::Data to_data(const cell::Proposal& proposal);
cell::Proposal to_proposal(const fb::Data& data);
fb::Data to_data(const cell::Award& award);
cell::Award to_award(const fb::Data& data);
fb::Data to_data(const cell::AwardReply& reply);
cell::AwardReply to_award_reply(const fb::Data& data);
fb::Data to_data(const cell::Release& release);
cell::Release to_release(const fb::Data& data);
// resource_id, kind, operations (comma-separated), position, dock, speed, angular_speed,
// reserved_by, waiting (comma-separated), queued_commands, busy.
fb::Data to_data(const cell::Capability& capability);

}  // namespace dds
