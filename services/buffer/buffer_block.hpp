#pragma once
// A part buffer: holds counts of part types and gives one part per "give" command. It knows
// no products: a part type is a name.
//
//   START (part_type)  ->  DONE, CAPABILITY (the stock changed)  or  FAIL (reason)

#include <map>
#include <string>

#include "services/node/device_block.hpp"

namespace fb {

class BufferBlock : public DeviceBlock {
 public:
  BufferBlock(std::string name, std::string resource_id, std::map<std::string, int> stock);
  const std::map<std::string, int>& stock() const { return stock_; }
  int count(const std::string& part_type) const;

 private:
  std::map<std::string, int> stock_;
};

}  // namespace fb
