#include "deploy/cellctl/cell_observer.hpp"

#include <nlohmann/json.hpp>

#include "capabilitiesPubSubTypes.h"
#include "commandsPubSubTypes.h"
#include "ordersPubSubTypes.h"
#include "services/dds/conversions.hpp"
#include "services/dds/endpoints.hpp"
#include "services/dds/sim_clock.hpp"

namespace cellctl {

struct CellObserver::Impl {
  dds::ParticipantPtr participant;
  std::unique_ptr<dds::SimClock> clock;
  std::unique_ptr<dds::Reader<cell::Capability, cell::CapabilityPubSubType>> capabilities;
  std::unique_ptr<dds::Reader<cell::OrderStatus, cell::OrderStatusPubSubType>> statuses;
  std::unique_ptr<dds::Reader<cell::CommandEvent, cell::CommandEventPubSubType>> events;
};

CellObserver::CellObserver(const dds::ParticipantSettings& settings) : impl_(std::make_unique<Impl>()) {
  impl_->participant = dds::make_participant("cellctl", settings);
  impl_->clock = std::make_unique<dds::SimClock>(impl_->participant);
  const auto changed = [this](auto&& f) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      f();
      ++version_;
      changed_at_ = std::chrono::system_clock::now();
    }
    changed_.notify_all();
  };
  impl_->capabilities = std::make_unique<dds::Reader<cell::Capability, cell::CapabilityPubSubType>>(
      impl_->participant, "cell/capabilities", dds::TopicKind::state,
      [this, changed](const cell::Capability& c) {
        changed([&] { resources_[c.resource_id().to_string()] = {c, true, std::chrono::system_clock::now()}; });
      },
      [this, changed](const cell::Capability& c) {
        changed([&] {
          ResourceView& r = resources_[c.resource_id().to_string()];
          r.capability = c;
          r.alive = false;
        });
      });
  impl_->statuses = std::make_unique<dds::Reader<cell::OrderStatus, cell::OrderStatusPubSubType>>(
      impl_->participant, "cell/orders/status", dds::TopicKind::state, [this, changed](const cell::OrderStatus& s) {
        changed([&] { orders_[s.order_id().to_string()] = s; });
        std::function<void(const cell::OrderStatus&)> callback;
        {
          std::lock_guard<std::mutex> lock(mutex_);
          callback = on_status_;
        }
        if (callback) callback(s);
      });
  impl_->events = std::make_unique<dds::Reader<cell::CommandEvent, cell::CommandEventPubSubType>>(
      impl_->participant, "cell/command_events", dds::TopicKind::events, [this, changed](const cell::CommandEvent& e) {
        changed([&] {
          command_events_.push_back({++command_seq_, e.resource_id().to_string(), e.order_id().to_string(),
                                     e.operation().to_string(), e.part().to_string(), e.command_id().to_string(),
                                     e.state(), e.reason().to_string(), e.sim_time(),
                                     std::chrono::system_clock::now()});
          if (command_events_.size() > kKeptCommandEvents) command_events_.pop_front();
        });
        std::lock_guard<std::mutex> lock(mutex_);
        if (!events_.is_open()) return;
        nlohmann::json line{{"t", e.sim_time()},
                            {"resource", e.resource_id().to_string()},
                            {"event", dds::state_name(e.state())},
                            {"operation", e.operation().to_string()},
                            {"part", e.part().to_string()},
                            {"order", e.order_id().to_string()},
                            {"command", e.command_id().to_string()}};
        if (e.state() == cell::SUCCEEDED && e.distance() > 0) {
          line["distance"] = e.distance();
          line["duration"] = e.duration();
        }
        if (e.reason().size() > 0) line["reason"] = e.reason().to_string();
        events_ << line.dump() << '\n';
        ++logged_;
        if (e.state() == cell::SUCCEEDED && e.operation() == "fetch") {
          line["event"] = "delivered";
          events_ << line.dump() << '\n';
          ++logged_;
        }
        events_.flush();
      });
}

CellObserver::~CellObserver() = default;

void CellObserver::log_events_to(const std::string& file) {
  std::lock_guard<std::mutex> lock(mutex_);
  events_.open(file, std::ios::trunc);
  if (!events_) throw std::runtime_error("cannot write " + file);
}

const dds::ParticipantPtr& CellObserver::participant() const { return impl_->participant; }

void CellObserver::on_status(std::function<void(const cell::OrderStatus&)> callback) {
  std::lock_guard<std::mutex> lock(mutex_);
  on_status_ = std::move(callback);
}

std::vector<std::string> CellObserver::wait_for_resources(const std::vector<std::string>& ids,
                                                          std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto missing = [&] {
    std::vector<std::string> out;
    for (const auto& id : ids) {
      const auto it = resources_.find(id);
      if (it == resources_.end() || !it->second.alive) out.push_back(id);
    }
    return out;
  };
  changed_.wait_for(lock, timeout, [&] { return missing().empty(); });
  return missing();
}

std::map<std::string, ResourceView> CellObserver::resources() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return resources_;
}

std::map<std::string, cell::OrderStatus> CellObserver::orders() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return orders_;
}

double CellObserver::sim_now() const { return impl_->clock->now(); }

void CellObserver::note_change() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++version_;
  }
  changed_.notify_all();
}

std::uint64_t CellObserver::wait_for_change(std::uint64_t seen, std::chrono::milliseconds timeout) const {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait_for(lock, timeout, [&] { return version_ != seen; });
  return version_;
}

std::chrono::system_clock::time_point CellObserver::changed_at() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return changed_at_;
}

std::vector<CommandHeard> CellObserver::command_events_after(std::uint64_t after) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<CommandHeard> out;
  for (auto it = command_events_.rbegin(); it != command_events_.rend() && it->seq > after; ++it) out.push_back(*it);
  return {out.rbegin(), out.rend()};
}

std::size_t CellObserver::events_logged() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return logged_;
}

}  // namespace cellctl
