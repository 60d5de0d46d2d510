#pragma once
// The life cycle of commands on one resource, as a ROS 2 action goal has it: accepted,
// executing (with progress), canceling, and succeeded, canceled or aborted. A resource
// service puts this block between its command topic and the block that drives its device;
// it knows nothing about what a command does. One command executes at a time; the others
// are refused (a device that cannot wait) or queued in arrival order (a device with a work
// queue, such as a mobile robot).
//
//   inputs                         outputs
//   COMMAND  (command_id, order_id) ACCEPTED             (command_id)
//   PROGRESS (progress, ...)       START                 (command_id)
//   DONE     (...)                 EXECUTING             (command_id, progress, ...)
//   FAIL     (reason, ...)         SUCCEEDED             (command_id, ...)
//   CANCEL   (command_id, order_id) ABORTED              (command_id, reason, ...)
//   STOPPED                        CANCELING, STOP       (command_id)
//                                  CANCELED              (command_id)
//                                  REJECTED              (command_id, reason)
//                                  IDLE: nothing executes and nothing waits any more
// A command accepted while the device is free starts at once (ACCEPTED says both); one that
// waited in the queue is EXECUTING (progress 0) when it starts.
// CANCEL of a queued command takes it out at once (CANCELED); of the executing one, asks the
// device to STOP (a device that finishes first: its outcome stands). A cancel counts only
// from the order the command came from (order_id, "" when not given): under DDS-Security
// only that order's twin can send it (docs/security.md).
// Data the device adds to PROGRESS, DONE and FAIL (a sim time, a distance) goes out with
// the event they cause.

#include <deque>
#include <map>
#include <string>

#include "services/runtime/basic_block.hpp"

namespace fb {

class CommandLifecycle : public BasicBlock {
 public:
  enum class WhenBusy { reject, queue };
  explicit CommandLifecycle(std::string name, WhenBusy when_busy = WhenBusy::reject);

  std::size_t queued() const { return queue_.size(); }

 private:
  Data with_id(Data data) const;
  void start_next();
  bool from_its_order(const Data& cancel) const;
  std::string command_;
  std::deque<std::string> queue_;
  std::map<std::string, std::string> order_of_;  // command (executing or queued) -> its order
};

}  // namespace fb
