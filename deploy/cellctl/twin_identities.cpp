#include "deploy/cellctl/twin_identities.hpp"

#include <algorithm>

#include "cell_idl/ordersPubSubTypes.h"
#include "services/dds/endpoints.hpp"

namespace cellctl {

struct TwinIdentities::Writer {
  explicit Writer(dds::ParticipantPtr participant) : bindings(std::move(participant), "cell/orders/twins", dds::TopicKind::state) {}
  dds::Writer<cell::TwinBinding, cell::TwinBindingPubSubType> bindings;
};

TwinIdentities::TwinIdentities(const std::vector<std::string>& names, dds::ParticipantPtr participant)
    : secure_(!names.empty()), free_(names.begin(), names.end()) {
  if (!secure_) return;
  writer_ = std::make_unique<Writer>(std::move(participant));
}

TwinIdentities::~TwinIdentities() = default;

std::optional<std::string> TwinIdentities::take() {
  if (!secure_) return std::string();
  if (free_.empty()) return std::nullopt;
  std::string identity = free_.front();
  free_.pop_front();
  return identity;
}

void TwinIdentities::give_back(const std::string& identity) {
  if (secure_ && !identity.empty() && std::find(free_.begin(), free_.end(), identity) == free_.end()) {
    free_.push_back(identity);
  }
}

void TwinIdentities::bind(const std::string& order, const std::string& identity) {
  if (!secure_) return;
  // The identity's binding to its last order ends (the readers end it too as this one comes,
  // dds::TwinBindings): a reader that joins later must not get both, in either order.
  if (const auto last = bound_.find(identity); last != bound_.end() && last->second != order) {
    cell::TwinBinding before;
    before.order_id(last->second);
    writer_->bindings.unregister(before);
  }
  cell::TwinBinding b;
  b.order_id(order);
  b.identity(identity);
  if (!writer_->bindings.write(b)) throw std::runtime_error("cannot bind order " + order + " to its twin " + identity);
  bound_[identity] = order;
}

Twin TwinIdentities::start(const std::string& order, const std::vector<std::string>& argv, const std::string& stdout_to) {
  const std::optional<std::string> identity = take();
  if (!identity) return {};
  try {
    bind(order, *identity);
    return {std::make_unique<Process>("twin-" + order, with_identity(argv, *identity), stdout_to), *identity};
  } catch (...) {
    give_back(*identity);
    throw;
  }
}

std::vector<std::string> with_identity(std::vector<std::string> argv, const std::string& identity) {
  if (!identity.empty()) argv.insert(argv.end(), {"--identity", identity});
  return argv;
}

}  // namespace cellctl
