#pragma once
// Twin start-up, as bench_cell and bench_security measure it: with cell-sim and a station
// running on the domain, `rounds` Cranfield twins, each stopped once it began virtual
// assembly. Started with their orders (cold), or handed their orders as standby twins that
// joined the cell 1.5 s before (deploy/cellctl/twin_pool.hpp, as cellctl up's desk does).

#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "deploy/cellctl/twin_pool.hpp"
#include "ordersPubSubTypes.h"
#include "tests/bench/bench_support.hpp"

namespace bench {

struct TwinLaunches {
  std::vector<double> first_status, begun;  // us from the start (or the order written)
  int never_begun = 0;                      // within 10 s
};

// `twin_args`: the twin and the cell's options (no order); `observer` reads the orders' status
// and, under security, binds each order to its twin's identity (one of `identities`).
inline TwinLaunches twin_launches(const dds::ParticipantPtr& observer, std::vector<std::string> twin_args, int rounds,
                                  bool standing_by, const std::string& tag,
                                  const std::vector<std::string>& identities = {}) {
  using namespace std::chrono_literals;
  std::mutex mutex;
  std::condition_variable changed;
  // The latest status per order (keep last 1: statuses in quick succession may coalesce).
  std::map<std::string, cell::OrderStatus> seen;
  dds::Reader<cell::OrderStatus, cell::OrderStatusPubSubType> statuses(
      observer, "cell/orders/status", dds::TopicKind::state, [&](const cell::OrderStatus& s) {
        {
          std::lock_guard<std::mutex> lock(mutex);
          seen[s.order_id().to_string()] = s;
        }
        changed.notify_all();
      });
  const auto order_args = [](const std::string& order) {
    return std::vector<std::string>{"--order", order, "--product", std::string(PRODUCTS_DIR) + "/cranfield/cranfield.aml",
                                    "--out", "/tmp/bench-twin", "--wait", "5"};
  };
  auto standby_args = twin_args;
  standby_args.push_back("--standby");
  cellctl::TwinIdentities ids(identities, observer);
  cellctl::TwinPool pool(standby_args, standing_by ? 1 : 0, ids);
  TwinLaunches out;
  for (int i = 0; i < rounds; ++i) {
    const std::string order = tag + (standing_by ? "-standby-" : "-cold-") + std::to_string(i);
    cellctl::Twin twin;
    if (standing_by) std::this_thread::sleep_for(1500ms);
    const auto start = Clock::now();
    if (standing_by) {
      twin = pool.take("twin-" + order, order, order_args(order));
      if (!twin.process) throw std::runtime_error("no standby twin");
      pool.tend();
    } else {
      auto argv = twin_args;
      const auto more = order_args(order);
      argv.insert(argv.end(), more.begin(), more.end());
      twin = ids.start(order, argv, "/dev/null");
      if (!twin.process) throw std::runtime_error("no twin identity free");
    }
    std::unique_lock<std::mutex> lock(mutex);
    if (changed.wait_for(lock, 10s, [&] { return seen.count(order) > 0; })) {
      out.first_status.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
    }
    // Planned, cell-sim answered, a station known: virtual assembly begins.
    const auto begun = [&] {
      const auto it = seen.find(order);
      return it != seen.end() && it->second.state() >= cell::VIRTUAL_ASSEMBLY;
    };
    if (changed.wait_for(lock, 10s, begun)) {
      out.begun.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
    } else {
      ++out.never_begun;
    }
    lock.unlock();
    twin.process->stop();
    ids.give_back(twin.identity);
  }
  return out;
}

inline void report(const std::string& what, const TwinLaunches& l) {
  report(what + " to its first status (Cranfield)", l.first_status);
  report(what + " to planned, cell-sim answered, virtual assembly begun (Cranfield)", l.begun);
  if (!l.begun.empty()) {
    std::cout << "  slowest " << *std::max_element(l.begun.begin(), l.begun.end()) / 1000 << " ms; " << l.never_begun
              << " never got there within 10 s" << std::endl;
  }
}

}  // namespace bench
