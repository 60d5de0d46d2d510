#pragma once
// The life cycle of one command on one resource, as a ROS 2 action goal has it: accepted,
// executing (with progress), canceling, and succeeded, canceled or aborted. A resource
// service puts this block between its command topic and the block that drives its device;
// it knows nothing about what the command does.
//
//   inputs                         outputs
//   COMMAND  (command_id)          ACCEPTED, START       (command_id)
//   PROGRESS (progress)            EXECUTING             (command_id, progress)
//   DONE                           SUCCEEDED             (command_id)
//   FAIL     (reason)              ABORTED               (command_id, reason)
//   CANCEL   (command_id)          CANCELING, STOP       (command_id)
//   STOPPED                        CANCELED              (command_id)
//                                  REJECTED              (command_id, reason)

#include "services/runtime/basic_block.hpp"

namespace fb {

class CommandLifecycle : public BasicBlock {
 public:
  explicit CommandLifecycle(std::string name);

 private:
  void reject(const Data& data);
  std::string command_;
};

}  // namespace fb
