#pragma once
// Twins started before their orders (`standby_twins:` in the deployment file). A new
// participant takes 0.3-0.6 s until the cell's processes match its endpoints (Fast DDS 2.9's
// endpoint discovery; docs/performance.md "Twin start-up"); a standby twin has joined the cell
// by the time an order comes, and reads the order's options on its standard input. Each
// order still gets a process of its own: a standby twin takes one order and ends with it.
// With security each standby twin has its identity (twin_identities.hpp) from its start.

#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "deploy/cellctl/processes.hpp"
#include "deploy/cellctl/twin_identities.hpp"

namespace cellctl {

class TwinPool {
 public:
  // `standby_argv`: a twin with --standby and the cell's options; `size` of them stand by,
  // each with an identity of `identities` (which must outlive the pool).
  TwinPool(std::vector<std::string> standby_argv, int size, TwinIdentities& identities,
           std::function<void(const std::string&)> log = {});
  ~TwinPool();

  // A standby twin bound to `order` and given its options (`order_args`, as on a twin's
  // command line), named `name`; no process when none stands by (then start one the usual way).
  Twin take(const std::string& name, const std::string& order, const std::vector<std::string>& order_args);
  // Replaces the standby twins that were taken or ended. Call often.
  void tend();
  std::size_t standing_by() const { return standby_.size(); }

 private:
  std::vector<std::string> argv_;
  std::size_t size_;
  TwinIdentities& identities_;
  std::function<void(const std::string&)> log_;
  std::deque<Twin> standby_;  // oldest first: the likeliest to have joined
  std::chrono::steady_clock::time_point not_before_{};
};

}  // namespace cellctl
