#pragma once
// A part buffer: holds counts of part types and gives one part per command. It knows no
// products: a part type is a name.
//
//   inputs                               outputs
//   COMMAND (command_id, resource_id,    ACCEPT (command_id): for the life cycle, when the
//            operation, part)                                 command is for this buffer
//   START   (command_id)                 DONE, FAIL (reason): back to the life cycle
//                                        STOCK (): the stock changed

#include <map>
#include <string>

#include "services/runtime/basic_block.hpp"

namespace fb {

class BufferBlock : public BasicBlock {
 public:
  BufferBlock(std::string name, std::string resource_id, std::map<std::string, int> stock);
  const std::map<std::string, int>& stock() const { return stock_; }
  const std::string& resource_id() const { return resource_id_; }

 private:
  std::string resource_id_;
  std::map<std::string, int> stock_;
  std::map<std::string, std::string> part_of_command_;
};

}  // namespace fb
