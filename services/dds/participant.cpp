#include "services/dds/participant.hpp"

#include <algorithm>
#include <iostream>
#include <map>
#include <mutex>
#include <stdexcept>
#include <vector>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/writer/WriterDiscoveryInfo.h>
#include <fastrtps/utils/IPLocator.h>

#include "cell_idl/simulationPubSubTypes.h"
#include "services/dds/twin_bindings.hpp"

namespace dds {

constexpr std::uint32_t kMaxParticipantsPerHost = 32;
// Every discovery port a participant on a host can take: a process's first participant takes
// the first free one of 100 (Fast DDS's mutation_tries), its second one past it.
constexpr std::uint32_t kDiscoveryPortsPerHost = 128;

// Says when another participant's lease ran out while it may still live (a process starved
// of CPU for the whole lease): until discovery matches the two again, what they write to
// each other is lost, and a call that gets no answer from a live resource is the sign.
// Keeps the partitions of every remote writer that has some (writer_speaks_for()).
// Holds what else is kept per participant: its identity, and the twins' bindings.
class DiscoveryLog : public eprosima::fastdds::dds::DomainParticipantListener {
 public:
  DiscoveryLog(std::string name, std::string identity) : name_(std::move(name)), identity_(std::move(identity)) {}

  const std::string& identity() const { return identity_; }
  std::shared_ptr<TwinBindings> bindings(const ParticipantPtr& participant) {
    // Not under mutex_: making the reader takes Fast DDS's locks, under which Fast DDS calls
    // on_publisher_discovery.
    std::lock_guard<std::mutex> lock(bindings_mutex_);
    if (!bindings_) bindings_ = std::make_shared<TwinBindings>(participant);
    return bindings_;
  }
  // Before the participant's entities are deleted: the bindings' reader is one of them.
  void drop_bindings() {
    std::lock_guard<std::mutex> lock(bindings_mutex_);
    bindings_.reset();
  }

  // Called before the writer is matched to any reader of ours, so before its first sample.
  // Kept when it goes: its last samples may still be taken after (a state topic's instance
  // that lost its writers). A few entries per process that ever wrote in a partition.
  void on_publisher_discovery(eprosima::fastdds::dds::DomainParticipant*,
                              eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override {
    using Info = eprosima::fastrtps::rtps::WriterDiscoveryInfo;
    if (info.status == Info::REMOVED_WRITER) return;
    const auto& names = info.info.m_qos.m_partition.names();
    if (names.empty()) return;
    std::lock_guard<std::mutex> lock(mutex_);
    partitions_[info.info.guid()] = std::vector<std::string>(names.begin(), names.end());
  }
  bool writes_in(const eprosima::fastrtps::rtps::GUID_t& writer, const std::string& partition) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = partitions_.find(writer);
    return it != partitions_.end() && std::find(it->second.begin(), it->second.end(), partition) != it->second.end();
  }
  void on_participant_discovery(eprosima::fastdds::dds::DomainParticipant*,
                                eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    if (info.status == eprosima::fastrtps::rtps::ParticipantDiscoveryInfo::DROPPED_PARTICIPANT) {
      std::cerr << name_ << ": DDS participant " << info.info.m_participantName.to_string()
                << " dropped: its discovery lease ran out\n";
    }
  }
  // Fast DDS logs why (a certificate of another CA, an expired one, permissions that do not
  // match); this line says that it refused, and whom.
  void onParticipantAuthentication(eprosima::fastdds::dds::DomainParticipant*,
                                   eprosima::fastrtps::rtps::ParticipantAuthenticationInfo&& info) override {
    if (info.status == eprosima::fastrtps::rtps::ParticipantAuthenticationInfo::UNAUTHORIZED_PARTICIPANT) {
      std::cerr << name_ << ": refused DDS participant " << info.guid
                << ": it failed authentication (no certificate, or one the cell's CA did not sign or that expired)\n";
    }
  }

 private:
  std::string name_;
  std::string identity_;
  std::mutex bindings_mutex_;
  std::shared_ptr<TwinBindings> bindings_;
  mutable std::mutex mutex_;
  std::map<eprosima::fastrtps::rtps::GUID_t, std::vector<std::string>> partitions_;
};

bool writer_speaks_for(const eprosima::fastdds::dds::DomainParticipant& participant,
                       const eprosima::fastrtps::rtps::GUID_t& writer, const std::string& resource_id) {
  if (writer.guidPrefix == participant.guid().guidPrefix) return true;  // ours: checked when created
  const auto* log = dynamic_cast<const DiscoveryLog*>(participant.get_listener());
  return !resource_id.empty() && log && log->writes_in(writer, resource_id);
}

std::string security_identity(const eprosima::fastdds::dds::DomainParticipant& participant) {
  const auto* log = dynamic_cast<const DiscoveryLog*>(participant.get_listener());
  return log ? log->identity() : "";
}

std::shared_ptr<TwinBindings> twin_bindings(const ParticipantPtr& participant) {
  // The listener is ours to change (make_participant made it); Fast DDS hands it out const.
  auto* log = const_cast<DiscoveryLog*>(dynamic_cast<const DiscoveryLog*>(participant->get_listener()));
  if (!log) throw std::logic_error("twin_bindings: not a participant of make_participant");
  return log->bindings(participant);
}

namespace {

// Fast DDS 2.9.1 walks the participant's list of local readers (WLP::readers_, a std::vector)
// without a lock whenever a matched writer's liveliness changes (its first sample, a lease
// that ran out), while creating a reader appends to that list from the creating thread. An
// append that grows the vector frees the storage under the walk: a mobile robot died so at
// start-up under TSan (SEGV in WLP::sub_liveliness_changed), and its cell never came up.
// Creating and deleting kReaderSlots readers before any reader of ours exists grows the list
// once, while no liveliness change can come (no reader is matched yet); later appends stay in
// place. A station, the largest, creates 16 readers (two resources of 8 each); creating and
// deleting 32 costs about 14 ms of a process's start (docs/performance.md).
constexpr int kReaderSlots = 32;

void reserve_reader_slots(eprosima::fastdds::dds::DomainParticipant& participant) {
  using namespace eprosima::fastdds::dds;
  TypeSupport type(new cell::ClockPubSubType());
  if (type.register_type(&participant) != ReturnCode_t::RETCODE_OK) return;
  Topic* topic = participant.create_topic("cell/reader_slots", type.get_type_name(), TOPIC_QOS_DEFAULT);
  Subscriber* subscriber = participant.create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  if (topic && subscriber) {
    DataReaderQos qos = DATAREADER_QOS_DEFAULT;
    qos.history().depth = 1;
    qos.resource_limits().max_samples = 1;
    qos.resource_limits().max_instances = 1;
    qos.resource_limits().max_samples_per_instance = 1;
    std::vector<DataReader*> readers;
    for (int i = 0; i < kReaderSlots; ++i) {
      if (DataReader* r = subscriber->create_datareader(topic, qos)) readers.push_back(r);
    }
    for (DataReader* r : readers) subscriber->delete_datareader(r);
  }
  if (subscriber) participant.delete_subscriber(subscriber);
  if (topic) participant.delete_topic(topic);
  participant.unregister_type(type.get_type_name());
}

eprosima::fastrtps::rtps::Locator_t udp_locator(const std::string& participant, const std::string& address, int port) {
  eprosima::fastrtps::rtps::Locator_t locator;
  locator.kind = LOCATOR_KIND_UDPv4;
  if (!eprosima::fastrtps::rtps::IPLocator::setIPv4(locator, address)) {
    throw std::runtime_error("DDS participant '" + participant + "': '" + address + "' is not an IPv4 address");
  }
  locator.port = static_cast<std::uint32_t>(port);
  return locator;
}

// A server is known to the others by its address and by a GUID prefix that its place in the
// list gives (Fast DDS's own scheme, as ROS_DISCOVERY_SERVER uses it): the clients never need
// to be told a prefix. Servers list each other, so that a client of one learns of the clients
// of the others, and a client lists them all, so that it goes on when one of them ends.
void use_discovery_servers(eprosima::fastdds::dds::DomainParticipantQos& qos, const std::string& name,
                           const DiscoverySettings& discovery) {
  using namespace eprosima::fastdds::rtps;
  auto& builtin = qos.wire_protocol().builtin;
  for (std::size_t i = 0; i < discovery.servers.size(); ++i) {
    const auto [address, port] = server_address(discovery.servers[i]);
    RemoteServerAttributes server;
    get_server_client_default_guidPrefix(static_cast<int>(i), server.guidPrefix);
    server.metatrafficUnicastLocatorList.push_back(udp_locator(name, address, port));
    if (static_cast<int>(i) == discovery.serve) {
      qos.wire_protocol().prefix = server.guidPrefix;
      builtin.metatrafficUnicastLocatorList.push_back(udp_locator(name, address, port));
    } else {
      builtin.discovery_config.m_DiscoveryServers.push_back(server);
    }
  }
  builtin.discovery_config.discoveryProtocol =
      discovery.serve >= 0 ? eprosima::fastrtps::rtps::DiscoveryProtocol::SERVER : eprosima::fastrtps::rtps::DiscoveryProtocol::CLIENT;
}

}  // namespace

ParticipantPtr make_participant(const std::string& name, const ParticipantSettings& settings) {
  using namespace eprosima::fastdds::dds;
  DomainParticipantQos qos = PARTICIPANT_QOS_DEFAULT;
  qos.name(name);
  // The addresses to use and to look for others at: loopback, or the deployment's network.
  std::vector<std::string> interfaces, peers;
  if (settings.interfaces.empty() && !settings.peers.empty()) {
    throw std::runtime_error("DDS participant '" + name + "': peers (--peer) need the host's own addresses (--interface)");
  }
  if (settings.localhost_only) {
    interfaces = peers = {"127.0.0.1"};
  } else if (!settings.interfaces.empty()) {
    interfaces = peers = settings.interfaces;  // the other processes on this host
    peers.insert(peers.end(), settings.peers.begin(), settings.peers.end());
  }
  if (!interfaces.empty()) {
    // UDP on those addresses only, no shared memory: Fast DDS 2.9.1's SHM transport drops
    // messages silently (a full port, a port of a process killed hard whose number a new
    // process reuses, a sender's full segment) and, once two processes see each other's SHM
    // locators, carries their discovery over SHM alone. Lost discovery and liveliness
    // messages were the multi-second discovery tail and a live buffer declared gone.
    qos.transport().use_builtin_transports = false;
    auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
    for (const auto& address : interfaces) udp->interfaceWhiteList.emplace_back(address);
    // An initial peer stands for the discovery ports of participants 0..N-1 at its address;
    // Fast DDS's default N is 4, and a cell has more processes than that (the sixth one was
    // never discovered). 32 covers a cell, its twins and cellctl.
    // A discovery server takes them as initial peers too, with every port a participant can
    // have: Fast DDS 2.9.1's server announces itself straight to the clients in its database,
    // and a client that has just arrived there may not have its sender yet (made when its
    // endpoints are matched, on another thread). Sending to a locator without one fails an
    // assertion in the transport's traffic statistics and aborts the server (fixed upstream
    // in Fast DDS PR #5704, 2025). Seen in CI with 57 participants starting at once; the
    // discovery server test provokes it. Initial peers get their senders when it starts.
    const bool serves = settings.discovery.serve >= 0;
    udp->maxInitialPeersRange = serves ? kDiscoveryPortsPerHost : kMaxParticipantsPerHost;
    qos.transport().user_transports.push_back(udp);
    if (settings.discovery.servers.empty() || serves) {
      for (const auto& address : peers) qos.wire_protocol().builtin.initialPeersList.push_back(udp_locator(name, address, 0));
    }
  }
  // Announce the participant every 0.5 s (by default) instead of 3 s: a first announcement that no one
  // heard (a process starting while others start) otherwise delays discovery by seconds.
  // The discovery lease stays Fast DDS's 20 s: with 5 s, a process starved of CPU for 5 s
  // (ten twins under ThreadSanitizer on two cores) was dropped by the others, and the pair
  // did not match again: every answer of a live buffer to one twin was lost. A process that
  // dies is noticed by the 5 s liveliness of its state writers (LivelinessKeeper).
  qos.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod =
      eprosima::fastrtps::Duration_t(settings.discovery.announce_every_s);
  qos.wire_protocol().builtin.discovery_config.leaseDuration = eprosima::fastrtps::Duration_t(20.0);
  if (settings.discovery.serve >= static_cast<int>(settings.discovery.servers.size())) {
    throw std::runtime_error("DDS participant '" + name + "': it serves discovery as server " +
                             std::to_string(settings.discovery.serve) + " of " +
                             std::to_string(settings.discovery.servers.size()));
  }
  if (!settings.discovery.servers.empty()) use_discovery_servers(qos, name, settings.discovery);
  std::string identity;
  if (!settings.security.dir.empty()) {
    identity = settings.security.identity.empty() ? name : settings.security.identity;
    const IdentityFiles files = identity_files(settings.security.dir, identity);
    check_identity(files, identity);
    apply_security(qos, files);
  }
  // One at a time in a process: Fast DDS 2.9 loads its XML profiles into static maps on a
  // participant's creation, and two threads creating participants at once (cellctl quote asks
  // several cells) raced there (LeakSanitizer found a node of such a map lost).
  static std::mutex creating;
  std::lock_guard<std::mutex> one_at_a_time(creating);
  DomainParticipantFactory* factory = DomainParticipantFactory::get_instance();
  auto log = std::make_shared<DiscoveryLog>(name, identity);
  DomainParticipant* participant = factory->create_participant(settings.domain_id, qos, log.get(), StatusMask::none());
  if (!participant) {
    throw std::runtime_error("cannot create DDS participant '" + name + "' on domain " +
                             std::to_string(settings.domain_id));
  }
  reserve_reader_slots(*participant);
  return ParticipantPtr(participant, [log](DomainParticipant* p) {
    log->drop_bindings();
    p->set_listener(nullptr);
    p->delete_contained_entities();
    DomainParticipantFactory::get_instance()->delete_participant(p);
  });
}

}  // namespace dds
