#pragma once
// The buffer service: a BufferBlock behind a CommandLifecycle, bound to the cell's command,
// command-event and capability topics. One resource, one queue.

#include <map>
#include <memory>
#include <string>

#include "services/dds/participant.hpp"
#include "services/runtime/resource.hpp"

namespace services {

struct BufferConfig {
  std::string id;
  std::map<std::string, int> stock;
  dds::ParticipantSettings dds;
  double liveliness_lease_s = 2.0;
};

class BufferService {
 public:
  explicit BufferService(const BufferConfig& config);
  ~BufferService();
  // Delivers events until `keep_running` turns false (checked every 100 ms).
  template <class Flag>
  void run(const Flag& keep_running) {
    while (keep_running) resource_.wait_and_run_one(std::chrono::milliseconds(100));
  }

 private:
  struct Impl;
  fb::Resource resource_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace services
