#pragma once
// Drives one block in a resource of its own and records what it emits, as 4diac FORTE's
// function-block test fixture does: send an event in, assert the events that come out.

#include <memory>
#include <utility>
#include <vector>

#include "services/runtime/resource.hpp"

namespace fb {

// Receives whatever the block under test emits; its inputs mirror the block's outputs.
class EventRecorder : public FunctionBlock {
 public:
  explicit EventRecorder(const FunctionBlock& observed) : FunctionBlock("recorder") {
    for (const auto& port : observed.outputs()) declare_input(port.name, port.with);
  }
  void receive(const Event& event) override { events.push_back(event); }
  std::vector<Event> events;
};

// The events' names, in order: what a test compares.
inline std::vector<std::string> event_names(const std::vector<Event>& events) {
  std::vector<std::string> out;
  for (const auto& e : events) out.push_back(e.name);
  return out;
}

template <class Block>
class BlockTestFixture {
 public:
  template <class... Args>
  explicit BlockTestFixture(Args&&... args) : resource_("test", 64) {
    block_ = &resource_.add(std::make_unique<Block>(std::forward<Args>(args)...));
    recorder_ = &resource_.add(std::make_unique<EventRecorder>(*block_));
    for (const auto& port : block_->outputs()) resource_.connect(block_->name(), port.name, "recorder", port.name);
  }

  Block& block() { return *block_; }

  // Sends one event to the block, runs the resource until idle, and returns what the block
  // emitted meanwhile, in order.
  std::vector<Event> send(const std::string& input, Data data = {}) {
    recorder_->events.clear();
    resource_.post(block_->name(), input, std::move(data));
    resource_.run_until_idle();
    return recorder_->events;
  }


 private:
  Resource resource_;
  Block* block_ = nullptr;
  EventRecorder* recorder_ = nullptr;
};

}  // namespace fb
