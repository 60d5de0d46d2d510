#pragma once
// The block that drives a resource's device (a buffer's stock, an arm, a mobile robot). It
// takes the commands addressed to its resource for operations it has, remembers them, and
// hands them to the command life cycle; when the life cycle starts one, the device's ECC
// gets START with the whole command (operation, part, path, ...), and answers with DONE or
// FAIL (and PROGRESS while it works).
//
//   inputs                                  outputs
//   COMMAND (command_id, resource_id,       ACCEPT   (command_id)    to the life cycle
//            operation, ...)                PROGRESS, DONE, FAIL     to the life cycle
//                                           REFUSE (command_id, reason, order_id, operation, part):
//                                           never accepted, see below
//   A command is checked before it is accepted: its fields (finite numbers, unit quaternions,
//   positions inside the cell's bounds, texts and paths within limits, and what the device
//   itself needs: an arm's grip opening within its gripper), then whether its order may command the
//   resource (`authorize`: it holds the award the command names). A command that fails is
//   REFUSEd with the reason, never queued or started.
//   A command that comes again (its sender heard nothing of it: a DDS match that was not
//   complete yet) is not carried out twice: while it is under way it is ignored (its events
//   will come); once it has ended, REPEAT gives its last event again.
//   START   (command_id) -> the ECC's START with the command's data; a command of an order
//           that has ended meanwhile fails at once ("order X has ended"), so a queue of
//           work for a failed order drains instead of being carried out
//   ORDER_ENDED, ORDER_ACTIVE (order_id): from the orders' status (an id may come again)
// A device adds its own inputs and outputs (replies from cell-sim, requests to it).

#include <deque>
#include <map>
#include <set>

#include <functional>

#include "services/blocks/sample_checks.hpp"
#include "services/runtime/basic_block.hpp"

namespace state {
class CellStore;
}

namespace fb {

class DeviceBlock : public BasicBlock {
 public:
  DeviceBlock(std::string name, std::string resource_id, std::set<std::string> operations,
              std::string initial_state = "READY");

  // "" when the command's order may command this resource, otherwise why not.
  using Authorize = std::function<std::string(const Data& command)>;

  const std::string& resource_id() const { return resource_id_; }
  void set_bounds(const CellBounds& bounds) { bounds_ = bounds; }
  void authorize_with(Authorize authorize) { authorize_ = std::move(authorize); }
  std::size_t refused() const { return refused_; }
  const std::string& last_refusal() const { return last_refusal_; }
  const std::set<std::string>& operations() const { return operations_; }
  // The command as it came (empty when unknown); ended() once its last event is out, with
  // that event's data (state, reason, ...), which REPEAT gives again if the command comes again.
  const Data& command(const std::string& command_id) const;
  void ended(const std::string& command_id, const Data& last_event);

  void receive(const Event& event) override;

  // The cell's durable state (docs/durable-state.md), where the process keeps one; the
  // device takes back what a process before it left there (a buffer its stock), and says
  // in a sentence what it did with what it held when that process ended ("" for nothing).
  std::string keep_state_in(state::CellStore& store);

 protected:
  state::CellStore* store() const { return store_; }
  virtual std::string recover() { return ""; }
  // An order ended (done, failed, its twin gone): a device frees what it kept for it.
  virtual void order_ended(const std::string& /*order*/) {}
  // Adds a device's own checks of a command to the common ones.
  virtual void check(const Data& /*command*/, SampleCheck& /*check*/) const {}
  const CellBounds& bounds() const { return bounds_; }

 private:
  std::string resource_id_;
  std::set<std::string> operations_;
  std::map<std::string, Data> commands_;
  std::map<std::string, Data> ended_;    // command id -> its command and last event, the newest few
  std::deque<std::string> ended_order_;  // oldest first
  std::set<std::string> ended_orders_;
  CellBounds bounds_;
  Authorize authorize_;
  state::CellStore* store_ = nullptr;
  std::size_t refused_ = 0;
  std::string last_refusal_;

  std::string problem_with(const Data& command) const;
};

}  // namespace fb
