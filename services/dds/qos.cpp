#include "services/dds/qos.hpp"

namespace dds {
namespace {

using namespace eprosima::fastdds::dds;


template <class Qos>
void apply(Qos& qos, TopicKind kind, const QosSettings& settings) {
  qos.reliability().kind = RELIABLE_RELIABILITY_QOS;
  // Fast DDS's default is 10 instances per writer and reader: the eleventh cell-sim request
  // (one instance per request id) was silently never delivered. 0 = unlimited in 2.9.
  qos.resource_limits().max_instances = 0;
  qos.resource_limits().max_samples_per_instance = 0;
  qos.resource_limits().max_samples = 0;
  qos.data_sharing().off();
  // Every type is bounded (idl/common.idl): payload buffers of the type's largest size, and
  // a sample larger than that is refused by Fast DDS on arrival, never reallocated for.
  qos.endpoint().history_memory_policy = eprosima::fastrtps::rtps::PREALLOCATED_MEMORY_MODE;
  qos.resource_limits().allocated_samples = 16;
  if (kind == TopicKind::state) {
    qos.durability().kind = TRANSIENT_LOCAL_DURABILITY_QOS;
    qos.history().kind = KEEP_LAST_HISTORY_QOS;
    qos.history().depth = 1;
    // Asserted per writer by the LivelinessKeeper (liveliness_keeper.hpp says why not AUTOMATIC,
    // and why by writing the last samples again).
    qos.liveliness().kind = MANUAL_BY_TOPIC_LIVELINESS_QOS;
    qos.liveliness().lease_duration = eprosima::fastrtps::Duration_t(settings.liveliness_lease_s);
  } else {
    qos.durability().kind = VOLATILE_DURABILITY_QOS;
    qos.history().kind = KEEP_ALL_HISTORY_QOS;
    // Readers take every sample as it comes; a reader this far behind is under a flood, and
    // a reliable writer then waits (its own write times out): the flood slows its sender.
    qos.resource_limits().max_samples = settings.max_queued;
  }
}

}  // namespace

DataWriterQos writer_qos(TopicKind kind, const QosSettings& settings) {
  DataWriterQos qos = DATAWRITER_QOS_DEFAULT;
  apply(qos, kind, settings);
  return qos;
}

DataReaderQos reader_qos(TopicKind kind, const QosSettings& settings) {
  DataReaderQos qos = DATAREADER_QOS_DEFAULT;
  apply(qos, kind, settings);
  return qos;
}

}  // namespace dds
