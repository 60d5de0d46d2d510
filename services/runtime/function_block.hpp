#pragma once
// A function block: named event inputs and outputs, each with the data names it carries.
// Blocks never call each other: they emit events, and the resource they run on delivers
// them along its connections, one at a time.

#include <string>
#include <vector>

#include "services/runtime/event.hpp"

namespace fb {

class Resource;

struct EventPort {
  std::string name;
  std::vector<std::string> with;  // data names carried (IEC 61499 WITH)
};

class FunctionBlock {
 public:
  explicit FunctionBlock(std::string name) : name_(std::move(name)) {}
  virtual ~FunctionBlock() = default;
  FunctionBlock(const FunctionBlock&) = delete;
  FunctionBlock& operator=(const FunctionBlock&) = delete;

  const std::string& name() const { return name_; }
  const std::vector<EventPort>& inputs() const { return inputs_; }
  const std::vector<EventPort>& outputs() const { return outputs_; }
  bool has_input(const std::string& event) const;
  bool has_output(const std::string& event) const;

  // Called by the resource for each event delivered to this block.
  virtual void receive(const Event& event) = 0;
  // Called on the resource's thread when its queue has been empty a while: what the block
  // could not finish within an event (a sample a slow reader had no room for) is retried here.
  virtual void idle() {}

 protected:
  void declare_input(std::string name, std::vector<std::string> with = {});
  void declare_output(std::string name, std::vector<std::string> with = {});
  // Sends an event from one of this block's outputs; the resource queues it for every
  // input connected to that output. Throws std::logic_error for an undeclared output.
  void emit(const std::string& output, Data data = {});
  // Queues an event for one of this block's own inputs, from any thread (a DDS listener);
  // throws EventQueueOverflow when the resource's queue is full.
  void post_to_self(const std::string& input, Data data = {});

 private:
  friend class Resource;
  std::string name_;
  std::vector<EventPort> inputs_;
  std::vector<EventPort> outputs_;
  Resource* resource_ = nullptr;
};

}  // namespace fb
