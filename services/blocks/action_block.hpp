#pragma once
// A service-interface block for local effects: each REQ runs a function (publish a state,
// write a log line), then CNF. Keeps side effects out of the blocks that decide.

#include <functional>

#include "services/runtime/function_block.hpp"

namespace fb {

class ActionBlock : public FunctionBlock {
 public:
  ActionBlock(std::string name, std::function<void(const Data&)> action)
      : FunctionBlock(std::move(name)), action_(std::move(action)) {
    declare_input("REQ");
    declare_output("CNF");
  }
  void receive(const Event& event) override {
    action_(event.data);
    emit("CNF");
  }

 private:
  std::function<void(const Data&)> action_;
};

}  // namespace fb
