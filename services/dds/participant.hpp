#pragma once
// DDS participants for the cell. Localhost-only unless the deployment says otherwise:
// built-in transports off, UDPv4 restricted to 127.0.0.1 (no shared memory: see
// participant.cpp), and 127.0.0.1 as the initial discovery peer. With that, Fast DDS 2.9
// sends nothing but loopback traffic.

#include <memory>
#include <string>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>

#include "services/dds/participant_settings.hpp"
#include "services/dds/security.hpp"

namespace dds {

// Deletes the participant and everything it created when the last owner lets go.
using ParticipantPtr = std::shared_ptr<eprosima::fastdds::dds::DomainParticipant>;

// Throws SecurityError when its identity's files are wrong, std::runtime_error when Fast DDS
// refuses to create it.
ParticipantPtr make_participant(const std::string& name, const ParticipantSettings& settings);

// Whether `writer` (a sample's writer) writes in the partition `resource_id`: under
// DDS-Security the partition is what the writer's permissions prove (endpoints.hpp,
// owned_topic), so a sample about a resource counts only from a writer in that resource's
// partition. A writer of `participant` itself counts (its permissions were checked when it
// was made); an unknown one does not.
bool writer_speaks_for(const eprosima::fastdds::dds::DomainParticipant& participant,
                       const eprosima::fastrtps::rtps::GUID_t& writer, const std::string& resource_id);

// The identity a participant was made with under DDS-Security; "" without.
std::string security_identity(const eprosima::fastdds::dds::DomainParticipant& participant);

}  // namespace dds
