#pragma once
// What the cell benchmarks share: percentiles, one line per figure, and command round trips
// (a command written, the time until its SUCCEEDED event comes back).

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <iostream>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "commandsPubSubTypes.h"
#include "services/dds/endpoints.hpp"

namespace bench {

using Clock = std::chrono::steady_clock;
using CommandWriter = dds::Writer<cell::Command, cell::CommandPubSubType>;
using EventReader = dds::Reader<cell::CommandEvent, cell::CommandEventPubSubType>;

inline double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * v.size()))];
}

inline void report(const std::string& what, const std::vector<double>& us) {
  std::cout << what << ": p50 " << percentile(us, 0.5) << " us, p99 " << percentile(us, 0.99) << " us (" << us.size()
            << " rounds)" << std::endl;
}

// Waits for the answer to each request, one at a time.
struct Answers {
  std::mutex mutex;
  std::condition_variable arrived;
  std::string last;
  void answer(const std::string& id) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      last = id;
    }
    arrived.notify_all();
  }
  bool wait(const std::string& id) {
    std::unique_lock<std::mutex> lock(mutex);
    return arrived.wait_for(lock, std::chrono::seconds(5), [&] { return last == id; });
  }
};

// Commands written on `topic` from `sender`, each timed until its SUCCEEDED event is heard
// on `answers_topic` by `listener`. `settings`: the writer's (a robot's gives go in its own
// partition, where a buffer under DDS-Security takes them).
class RoundTrips {
 public:
  RoundTrips(const dds::ParticipantPtr& sender, const dds::ParticipantPtr& listener, const std::string& topic,
             const std::string& answers_topic, const dds::QosSettings& settings = {})
      : reader_(listener, answers_topic, dds::TopicKind::events,
                [this](const cell::CommandEvent& e) {
                  if (e.state() == cell::SUCCEEDED) answers_.answer(e.command_id().to_string());
                }),
        writer_(sender, topic, dds::TopicKind::events, settings) {
    if (!writer_.wait_for_readers(1, std::chrono::seconds(20))) throw std::runtime_error("nobody reads " + topic);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the reader's side of the match, too
  }

  // One command's round trip, us.
  double once(const cell::Command& c) {
    const auto start = Clock::now();
    writer_.write(c);
    if (!answers_.wait(c.command_id().to_string())) throw std::runtime_error("no answer to " + c.command_id().to_string());
    return std::chrono::duration<double, std::micro>(Clock::now() - start).count();
  }

 private:
  Answers answers_;
  EventReader reader_;
  CommandWriter writer_;
};

// `rounds` round trips after 20 warm-up rounds, one after another; `make(i)` makes the i-th.
inline std::vector<double> round_trips(const dds::ParticipantPtr& sender, const dds::ParticipantPtr& listener,
                                       const std::string& topic, const std::string& answers_topic, int rounds,
                                       const std::function<cell::Command(int)>& make,
                                       const dds::QosSettings& settings = {}) {
  RoundTrips trips(sender, listener, topic, answers_topic, settings);
  std::vector<double> us;
  for (int i = -20; i < rounds; ++i) {
    const double t = trips.once(make(i + 100));
    if (i >= 0) us.push_back(t);
  }
  return us;
}

}  // namespace bench
