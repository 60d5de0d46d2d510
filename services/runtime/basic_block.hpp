#pragma once
// A basic function block: its behaviour is an execution control chart (ECC), a state
// machine whose transitions fire on an event and a guard, run an action (which may emit
// events) and enter the next state. An event that no transition of the current state takes
// is consumed and counted, as IEC 61499 does.
//
// The state is whatever type the block names its states by: an enum for a chart written
// out in its header, a string for the small charts of the cell's devices. Every change of
// state is a transition: an action that finds where the chart must go next (a script done, a
// failure in the middle of it) raises an internal event, which the chart takes once the
// action is over (run to completion), by a transition like any other.

#include <deque>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "services/runtime/function_block.hpp"

namespace fb {

template <class State>
class BasicChart : public FunctionBlock {
 public:
  using Guard = std::function<bool(const Data&)>;
  using Action = std::function<void(const Data&)>;

  BasicChart(std::string name, State initial_state) : FunctionBlock(std::move(name)), state_(std::move(initial_state)) {}

  const State& state() const { return state_; }
  std::size_t unhandled_events() const { return unhandled_; }

  void receive(const Event& event) override {
    take(event);
    while (!raised_.empty()) {
      const Event internal = std::move(raised_.front());
      raised_.pop_front();
      take(internal);
    }
  }

 protected:
  // Transitions are tried in the order they were added.
  void transition(State from, std::string event, State to, Action action = {}, Guard guard = {}) {
    transitions_.push_back({std::move(from), std::move(event), std::move(to), std::move(action), std::move(guard)});
  }
  // An internal event, taken after the transition under way (and the internal events raised
  // before it).
  void raise(std::string event, Data data = {}) { raised_.push_back({std::move(event), std::move(data)}); }

 private:
  void take(const Event& event) {
    for (const auto& t : transitions_) {
      if (!(t.from == state_) || t.event != event.name || (t.guard && !t.guard(event.data))) continue;
      state_ = t.to;  // entered before the action, so that events the action emits see it
      if (t.action) t.action(event.data);
      return;
    }
    ++unhandled_;
  }

  struct Transition {
    State from;
    std::string event;
    State to;
    Action action;
    Guard guard;
  };
  State state_;
  std::vector<Transition> transitions_;
  std::deque<Event> raised_;
  std::size_t unhandled_ = 0;
};

using BasicBlock = BasicChart<std::string>;

}  // namespace fb
