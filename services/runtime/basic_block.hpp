#pragma once
// A basic function block: its behaviour is an execution control chart (ECC), a state
// machine whose transitions fire on an event and a guard, run an action (which may emit
// events) and enter the next state. An event that no transition of the current state takes
// is consumed and counted, as IEC 61499 does.

#include <functional>
#include <string>
#include <vector>

#include "services/runtime/function_block.hpp"

namespace fb {

class BasicBlock : public FunctionBlock {
 public:
  using Guard = std::function<bool(const Data&)>;
  using Action = std::function<void(const Data&)>;

  BasicBlock(std::string name, std::string initial_state);

  const std::string& state() const { return state_; }
  std::size_t unhandled_events() const { return unhandled_; }
  void receive(const Event& event) override;

 protected:
  // Transitions are tried in the order they were added.
  void transition(std::string from, std::string event, std::string to, Action action = {}, Guard guard = {});

  // For an action whose outcome decides where the chart goes (a failure in the middle of a
  // script): enters `state` instead of the transition's own target.
  void enter(std::string state) { state_ = std::move(state); }

 private:
  struct Transition {
    std::string from, event, to;
    Action action;
    Guard guard;
  };
  std::string state_;
  std::vector<Transition> transitions_;
  std::size_t unhandled_ = 0;
};

}  // namespace fb
