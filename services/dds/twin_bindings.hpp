#pragma once
// Which twin speaks for which order, under DDS-Security (docs/security.md). Each twin has an
// identity of its own (twin-1 .. twin-N) and writes its order's topics in the DDS partition of
// that name, which its permissions alone allow; whoever starts a twin publishes the binding
// order -> identity on cell/orders/twins, which only cellctl's identities may write. A reader
// of an order's topics (endpoints.hpp, order_scoped_topic) takes a sample only from a writer
// in the partition its order is bound to.

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "services/dds/participant.hpp"

namespace dds {

class TwinBindings {
 public:
  // `participant` must outlive this (make_participant's deleter drops it first).
  explicit TwinBindings(const ParticipantPtr& participant);
  ~TwinBindings();
  TwinBindings(const TwinBindings&) = delete;
  TwinBindings& operator=(const TwinBindings&) = delete;

  // The identity the order is bound to; nullopt while no binding came.
  std::optional<std::string> identity_of(const std::string& order) const;
  // How many bindings came: what waited for one needs a look only when this changed.
  unsigned generation() const { return generation_.load(); }

  // `changed` is called (on a DDS thread) after each new binding; until forget(id), which
  // waits for a call under way. A call must not make or delete a reader of an order's topic.
  int listen(std::function<void()> changed);
  void forget(int id);

 private:
  void bind(const std::string& order, const std::string& identity);

  mutable std::mutex mutex_;
  std::map<std::string, std::string> identities_;  // order -> identity
  std::atomic<unsigned> generation_{0};
  std::mutex listeners_mutex_;  // held while listeners are called: forget() waits for them
  std::map<int, std::function<void()>> listeners_;
  int next_listener_ = 0;
  struct Subscription;
  std::unique_ptr<Subscription> subscription_;
};

// The participant's bindings, made on first use (a reader of cell/orders/twins).
std::shared_ptr<TwinBindings> twin_bindings(const ParticipantPtr& participant);

}  // namespace dds
