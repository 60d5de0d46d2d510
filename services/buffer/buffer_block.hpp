#pragma once
// A part buffer: holds counts of part types and gives one part per "give" command. It knows
// no products: a part type is a name. An award keeps parts for the order that won it, so
// that two orders never count on the same part; what an order does not take goes back to
// the free stock when the order ends.
//
//   AWARDED (order_id, part_type, count): keep that many for the order
//   START (order_id, part_type, part, destination: who takes it)  ->  DONE, CAPABILITY (the
//         stock changed)  or  FAIL (reason)
// With the cell's durable state, the stock is the stored one, and a part given is recorded
// as in transit with whoever took it, in the same transaction that counts it out.

#include <map>
#include <string>

#include "services/node/device_block.hpp"

namespace fb {

class BufferBlock : public DeviceBlock {
 public:
  BufferBlock(std::string name, std::string resource_id, std::map<std::string, int> stock);
  const std::map<std::string, int>& stock() const { return stock_; }
  int count(const std::string& part_type) const;
  // Not kept for any order.
  int free(const std::string& part_type) const;

 private:
  void order_ended(const std::string& order) override;
  std::string recover() override;
  void check(const Data& command, SampleCheck& check) const override;

  std::map<std::string, int> stock_;
  std::map<std::string, std::map<std::string, int>> kept_;  // order -> type -> parts kept for it
};

}  // namespace fb
