#pragma once
// Twins started before their orders (`standby_twins:` in the deployment file). A new
// participant takes 0.3-0.6 s until the cell's processes match its endpoints (Fast DDS 2.9's
// endpoint discovery; docs/performance.md "Twin start-up"); a standby twin has joined the cell
// by the time an order comes, and reads the order's options on its standard input. Each
// order still gets a process of its own: a standby twin takes one order and ends with it.

#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "deploy/cellctl/processes.hpp"

namespace cellctl {

class TwinPool {
 public:
  // `standby_argv`: a twin with --standby and the cell's options; `size` of them stand by.
  TwinPool(std::vector<std::string> standby_argv, int size, std::function<void(const std::string&)> log = {});

  // A standby twin given the order's options (`order_args`, as on a twin's command line),
  // named `name`; nullptr when none stands by (then start one the usual way).
  std::unique_ptr<Process> take(const std::string& name, const std::vector<std::string>& order_args);
  // Replaces the standby twins that were taken or ended. Call often.
  void tend();
  std::size_t standing_by() const { return standby_.size(); }

 private:
  std::vector<std::string> argv_;
  std::size_t size_;
  std::function<void(const std::string&)> log_;
  std::deque<std::unique_ptr<Process>> standby_;  // oldest first: the likeliest to have joined
  std::chrono::steady_clock::time_point not_before_{};
};

}  // namespace cellctl
