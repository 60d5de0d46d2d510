#pragma once
// The buffer service: a BufferBlock on a resource node (commands, life cycle, contract net,
// capability with its stock). One resource, one queue. Buffers are shared: every order may
// take parts from them.

#include <map>
#include <memory>
#include <string>

#include "services/node/heartbeat.hpp"
#include "services/node/resource_node.hpp"

namespace services {

struct BufferConfig {
  NodeConfig node;
  std::map<std::string, int> stock;
  dds::ParticipantSettings dds;
};

class BufferService {
 public:
  explicit BufferService(BufferConfig config);
  ~BufferService();
  // Delivers events until `keep_running` turns false (checked every 100 ms), beating the
  // supervisor's heartbeat as it goes.
  template <class Flag>
  void run(const Flag& keep_running) {
    Heartbeat heartbeat;
    while (keep_running) {
      resource_.wait_and_run_one(std::chrono::milliseconds(100));
      heartbeat.beat();
    }
  }

 private:
  fb::Resource resource_;
  std::unique_ptr<ResourceNode> node_;
};

}  // namespace services
