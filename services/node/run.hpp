#pragma once
// Runs resources until a flag (set by a signal handler) turns false: each resource on a thread
// of its own, delivering its events one at a time.

#include <semaphore.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>

#include "services/node/heartbeat.hpp"
#include "services/node/started_by.hpp"
#include "services/runtime/resource.hpp"

namespace services {

// The process gets SIGTERM when the process that started it ends, however it ends: a cell or
// a twin never outlives the cellctl (or test) that started it. One whose starter ended before
// this call (it would never get the signal) gets it at once, where the starter said its pid.
inline void stop_with_parent() {
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (const char* parent = std::getenv(kStartedByVariable); parent && std::atol(parent) != ::getppid()) std::raise(SIGTERM);
}

// A process asked to stop ends within this, however its teardown goes: in CI a robot whose
// cellctl up was killed got SIGTERM and ran on for minutes (left on the domain after the chaos
// test's `cellctl down`, under TSan). Where it hung is not found; the twin's known hang is in
// Fast DDS 2.9.1's deletion of endpoints, which has known deadlocks (eProsima/Fast-DDS#4026).
constexpr std::chrono::seconds kStopLimit{20};

namespace detail {
// Set by a signal handler, read by the process's threads: a lock-free atomic is safe for both.
inline std::atomic<bool> running{true};
inline sem_t stop_asked;  // posted by the handler (sem_post is async-signal-safe)
inline void stop_running(int) {
  running = false;
  ::sem_post(&stop_asked);
}
inline void exit_if_stop_hangs() {
  ::sem_init(&stop_asked, 0, 0);
  std::thread([] {
    while (::sem_wait(&stop_asked) != 0) {
    }
    std::this_thread::sleep_for(kStopLimit);
    std::fprintf(stderr, "error: still running %d s after it was asked to stop (a hang in its teardown): exiting\n",
                 static_cast<int>(kStopLimit.count()));
    std::_Exit(1);
  }).detach();
}
}  // namespace detail

// Queues an event of the process's own for a resource whose thread has not started (its
// INIT): where the queue is full, it first delivers what came. Sixty twins' calls filled a
// station's 256 while its arm's node started, and the station died of its refused INIT.
inline void post_when_room(fb::Resource& resource, const std::string& block, const std::string& input) {
  for (;;) {
    try {
      return resource.post(block, input);
    } catch (const fb::EventQueueOverflow&) {
      resource.run_one();
    }
  }
}

// The flag of run_until_signalled(), for a process's other functions.
inline const std::atomic<bool>& running_flag() { return detail::running; }

// The flag a cell process runs on: cleared by SIGINT or SIGTERM, and so when the process that
// started it ends (stop_with_parent); kStopLimit after that the process exits whatever it is
// doing. Call once, after the command line is read.
inline const std::atomic<bool>& run_until_signalled() {
  detail::exit_if_stop_hangs();
  std::signal(SIGINT, detail::stop_running);
  std::signal(SIGTERM, detail::stop_running);
  stop_with_parent();
  return detail::running;
}

// Armed when it goes out of scope: ends the process with `code` if it still runs `limit`
// later. Declared after a process's DDS entities, it is destroyed before them: their teardown
// may not hang the process (a twin once never ended after its order was interrupted, its
// participant silent, and the order waited for ever for it to end; the cause, inside Fast DDS
// 2.9.1's deletion of endpoints, is not found yet).
class ExitWatchdog {
 public:
  explicit ExitWatchdog(std::chrono::seconds limit) : limit_(limit) {}
  ~ExitWatchdog() {
    std::thread([limit = limit_, code = code_] {
      std::this_thread::sleep_for(limit);
      std::fprintf(stderr, "its end took more than %d s: exiting with %d\n", static_cast<int>(limit.count()), code);
      std::_Exit(code);
    }).detach();
  }
  ExitWatchdog(const ExitWatchdog&) = delete;
  ExitWatchdog& operator=(const ExitWatchdog&) = delete;
  // `return watchdog.exit(code);`
  int exit(int code) { return code_ = code; }

 private:
  std::chrono::seconds limit_;
  int code_ = 1;
};

// Each resource on a thread of its own; this thread beats the heartbeat while every one of
// them turns (a resource stuck in a call stops the beats, and its supervisor restarts us).
inline void run_until_stopped(const std::vector<fb::Resource*>& resources, const std::atomic<bool>& running) {
  std::vector<std::atomic<unsigned long>> turns(resources.size());
  std::vector<std::thread> threads;
  for (std::size_t i = 0; i < resources.size(); ++i) {
    threads.emplace_back([r = resources[i], &turn = turns[i], &running] {
      while (running) {
        r->wait_and_run_one(std::chrono::milliseconds(100));
        ++turn;
      }
    });
  }
  Heartbeat heartbeat;
  std::vector<unsigned long> seen(resources.size(), 0);
  while (running) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    bool all_turned = true;
    for (std::size_t i = 0; i < turns.size(); ++i) all_turned &= turns[i] != seen[i];
    if (!all_turned) continue;
    for (std::size_t i = 0; i < turns.size(); ++i) seen[i] = turns[i];
    heartbeat.beat();
  }
  for (auto& t : threads) t.join();
}

}  // namespace services
