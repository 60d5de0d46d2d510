#include "services/dds/twin_bindings.hpp"

#include <vector>

#include "cell_idl/ordersPubSubTypes.h"
#include "services/dds/endpoints.hpp"

namespace dds {

struct TwinBindings::Subscription {
  template <class... Args>
  explicit Subscription(Args&&... args) : reader(std::forward<Args>(args)...) {}
  Reader<cell::TwinBinding, cell::TwinBindingPubSubType> reader;
};

TwinBindings::TwinBindings(const ParticipantPtr& participant)
    // Not an owner: the participant's deleter drops the bindings before it deletes anything.
    : subscription_(std::make_unique<Subscription>(
          ParticipantPtr(participant.get(), [](auto*) {}), "cell/orders/twins", TopicKind::state,
          [this](const cell::TwinBinding& b) { bind(b.order_id().to_string(), b.identity().to_string()); })) {}

TwinBindings::~TwinBindings() = default;

std::optional<std::string> TwinBindings::identity_of(const std::string& order) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = identities_.find(order);
  if (it == identities_.end()) return std::nullopt;
  return it->second;
}

int TwinBindings::listen(std::function<void()> changed) {
  std::lock_guard<std::mutex> lock(listeners_mutex_);
  listeners_[next_listener_] = std::move(changed);
  return next_listener_++;
}

void TwinBindings::forget(int id) {
  std::lock_guard<std::mutex> lock(listeners_mutex_);
  listeners_.erase(id);
}

// A binding lasts when its writer goes (cellctl up restarted): the twin it names may still run.
// An identity speaks for one order at a time: identities are pooled, and the twin that had it
// before has ended, so its binding to a new order ends the one before (the next twin of that
// identity cannot write for the order of the last).
void TwinBindings::bind(const std::string& order, const std::string& identity) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto it = identities_.begin(); it != identities_.end();) {
      it = it->second == identity && it->first != order ? identities_.erase(it) : std::next(it);
    }
    identities_[order] = identity;
  }
  ++generation_;
  std::lock_guard<std::mutex> lock(listeners_mutex_);
  for (const auto& [id, changed] : listeners_) changed();
}

}  // namespace dds
