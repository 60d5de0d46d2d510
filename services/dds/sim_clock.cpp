#include "services/dds/sim_clock.hpp"

#include <algorithm>

#include "services/dds/endpoints.hpp"
#include "simulationPubSubTypes.h"

namespace dds {

struct SimClock::Impl {
  std::unique_ptr<Reader<cell::Clock, cell::ClockPubSubType>> reader;
};

SimClock::SimClock(ParticipantPtr participant) : impl_(std::make_unique<Impl>()) {
  impl_->reader = std::make_unique<Reader<cell::Clock, cell::ClockPubSubType>>(
      std::move(participant), "cell/clock", TopicKind::state, [this](const cell::Clock& c) {
        std::lock_guard<std::mutex> lock(mutex_);
        sim_time_ = c.sim_time();
        factor_ = c.real_time_factor();
        received_ = std::chrono::steady_clock::now();
        running_ = true;
      });
}

SimClock::~SimClock() = default;

// Never backwards: a clock sample that arrives late would otherwise pull the estimate back.
double SimClock::now() const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!running_) return floor_;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - received_).count();
  floor_ = std::max(floor_, sim_time_ + wall * factor_);
  return floor_;
}

void SimClock::observe(double sim_time) {
  std::lock_guard<std::mutex> lock(mutex_);
  floor_ = std::max(floor_, sim_time);
}

bool SimClock::running() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return running_;
}

double SimClock::real_time_factor() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return factor_;
}

}  // namespace dds
