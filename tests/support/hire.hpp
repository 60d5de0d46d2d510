#pragma once
// A test that commands a resource over DDS must first hire it, as a twin does: a call for
// proposals, the resource's bid, an award, its confirmation. Returns the award (the call id)
// that the commands then name, or "" (with the reason in `why`) if the resource did not bid
// or confirm within the time.

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>

#include "negotiationPubSubTypes.h"
#include "services/dds/endpoints.hpp"

namespace test {

// What the call asks besides the operation: the station the work is at (an arm's), the type
// and count of parts (a buffer's give).
struct CallDetails {
  std::string station, part_type;
  int count = 0;
};

inline std::string hire(const dds::ParticipantPtr& participant, const std::string& resource, const std::string& order,
                        const std::string& operation, const CallDetails& details = {}, std::string* why = nullptr,
                        std::chrono::seconds within = std::chrono::seconds(10)) {
  std::mutex mutex;
  std::condition_variable changed;
  bool proposed = false, replied = false, confirmed = false;
  std::string reason;
  const std::string call_id = order + "/" + operation + "/" + resource;
  dds::Reader<cell::Proposal, cell::ProposalPubSubType> proposals(
      participant, "cell/negotiation/proposals", dds::TopicKind::events, [&](const cell::Proposal& p) {
        if (p.call_id().to_string() != call_id || p.resource_id().to_string() != resource) return;
        std::lock_guard<std::mutex> lock(mutex);
        proposed = p.available();
        reason = p.reason().to_string();
        changed.notify_all();
      });
  dds::Reader<cell::AwardReply, cell::AwardReplyPubSubType> replies(
      participant, "cell/negotiation/replies", dds::TopicKind::events, [&](const cell::AwardReply& r) {
        if (r.call_id().to_string() != call_id) return;
        std::lock_guard<std::mutex> lock(mutex);
        replied = true;
        confirmed = r.confirmed();
        reason = r.reason().to_string();
        changed.notify_all();
      });
  dds::Writer<cell::CallForProposals, cell::CallForProposalsPubSubType> calls(participant, "cell/negotiation/calls",
                                                                              dds::TopicKind::events);
  dds::Writer<cell::Award, cell::AwardPubSubType> awards(participant, "cell/negotiation/awards", dds::TopicKind::events);
  const auto deadline = std::chrono::steady_clock::now() + within;
  cell::CallForProposals call;
  call.call_id(call_id);
  call.order_id(order);
  call.operation(operation);
  call.part_type(details.part_type);
  call.count(details.count);
  call.station(details.station);
  std::unique_lock<std::mutex> lock(mutex);
  // Called again until the resource's reader has matched and it bids (or refuses).
  while (!proposed && reason.empty() && std::chrono::steady_clock::now() < deadline) {
    lock.unlock();
    calls.write(call);
    lock.lock();
    changed.wait_for(lock, std::chrono::milliseconds(200), [&] { return proposed || !reason.empty(); });
  }
  if (proposed) {
    cell::Award award;
    award.call_id(call_id);
    award.resource_id(resource);
    award.order_id(order);
    award.lease(60);
    lock.unlock();
    awards.wait_for_readers(1, within);
    awards.write(award);
    lock.lock();
    changed.wait_until(lock, deadline, [&] { return replied; });
  }
  if (why) *why = reason.empty() && !confirmed ? "no answer from " + resource : reason;
  return confirmed ? call_id : "";
}

}  // namespace test
