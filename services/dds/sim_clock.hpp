#pragma once
// The cell's simulated time as a process sees it: cell-sim publishes its clock (sim time and
// real-time factor); between samples the time runs on with the wall clock. Times seen in
// messages (a command's issue time, a motion's end) push it forward, so that what a process
// does after hearing of an event is never stamped earlier than that event.

#include <chrono>
#include <memory>
#include <mutex>

#include "services/dds/participant.hpp"

namespace dds {

class SimClock {
 public:
  explicit SimClock(ParticipantPtr participant);
  ~SimClock();

  double now() const;
  void observe(double sim_time);
  bool running() const;  // a clock sample has arrived
  double real_time_factor() const;

 private:
  struct Impl;
  mutable std::mutex mutex_;
  double sim_time_ = 0;
  double factor_ = 0;
  bool running_ = false;
  std::chrono::steady_clock::time_point received_;
  mutable double floor_ = 0;  // the latest time handed out or observed
  std::unique_ptr<Impl> impl_;
};

}  // namespace dds
