#pragma once
// A content filter that Fast DDS runs at the writer: a reader of cell/sim/replies gets its
// own replies only, a twin of cell/command_events its own order's events, and the writer
// sends the rest to no one. Sixty twins each reading every reply of the cell made cell-sim's
// traffic grow with the square of the orders (and its repairs of lost samples with it).
//
// Fast DDS's own DDS-SQL filter reads a sample through its type's TypeObject, which these
// types do not have (idl/CMakeLists.txt says why); this one reads it with the type's own
// code. Its expression is a field's name, its parameters the values that pass:
//   expression "requester", parameters {"arm-1", "arm-1/node"}
// A field it does not know for the type is refused when the filtered topic is made.

#include <fastdds/dds/domain/DomainParticipant.hpp>

namespace dds {

inline constexpr const char* kFieldFilter = "CELL_FIELD_IN";

// On every participant (make_participant does it): a writer filters for its readers only with
// the filter's class registered on its own participant too.
void register_field_filter(eprosima::fastdds::dds::DomainParticipant& participant);

}  // namespace dds
