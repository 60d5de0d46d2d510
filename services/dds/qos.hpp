#pragma once
// Every topic's QoS, in one place. Two kinds of topic carry the cell's traffic:
//  - state (capabilities, order status, the clock): keyed, reliable, transient-local, the
//    last sample per instance, writer liveliness with a lease (kept by LivelinessKeeper), so
//    late joiners see the current state and a dead writer's instances go NOT_ALIVE_NO_WRITERS;
//  - events (commands, command events, negotiation messages): unkeyed, reliable, volatile,
//    every sample kept until taken, up to a bound.
// Samples live in buffers of their type's largest size: an oversized one is dropped on arrival.

#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

#include <string>
#include <vector>

namespace dds {

enum class TopicKind { state, events };

struct QosSettings {
  double liveliness_lease_s = 5.0;  // a state writer silent this long is taken for dead
  // Events: samples a reader holds before it has taken them, and a writer before every reader
  // has them. Buffers grow to this and never shrink.
  int max_queued = 4096;
  // The DDS partitions of the endpoint's publisher or subscriber; empty: the default one
  // (a reader of an owned topic: every partition; see owned_topic()).
  std::vector<std::string> partitions;
};

// A resource's command topic: one reader, commanded one step at a time by the orders that
// hired it; a flood fills this little and then waits at its sender.
inline QosSettings command_qos() {
  QosSettings s;
  s.max_queued = 64;
  return s;
}

// A resource's writers of its events (command events, proposals, award replies, its requests
// to cell-sim: ResourceNode's publish blocks and its overflow answers). Samples its readers have not yet
// acknowledged stay in the writer's history, whose buffers grow to the bound and never shrink;
// a backlog past it waits in the writer's Outbox, whose memory is given back. At 4096 a flood
// of 10 000 refused commands, read slowly on a loaded machine, left the station 22 MB of
// history buffers (two writers of 2.3 kB samples).
inline QosSettings own_events_qos(QosSettings s) {
  s.max_queued = 256;
  return s;
}

eprosima::fastdds::dds::DataWriterQos writer_qos(TopicKind kind, const QosSettings& settings = {});
eprosima::fastdds::dds::DataReaderQos reader_qos(TopicKind kind, const QosSettings& settings = {});

}  // namespace dds
