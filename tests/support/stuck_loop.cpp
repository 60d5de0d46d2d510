// A cell process whose loop gets stuck: it beats its heartbeat (services::Heartbeat) for the
// seconds its argument says, then stops beating and runs on, as a loop stuck in a deadlocked
// call would. With 0 it never beats, as a process that knows nothing of heartbeats.

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <thread>

#include "services/node/heartbeat.hpp"
#include "services/node/run.hpp"

int main(int argc, char** argv) {
  const std::atomic<bool>& running = services::run_until_signalled();
  const auto beat_for = std::chrono::seconds(argc > 1 ? std::atol(argv[1]) : 0);
  const auto until = std::chrono::steady_clock::now() + beat_for;
  services::Heartbeat heartbeat;
  std::cout << "running" << std::endl;
  while (running) {
    if (std::chrono::steady_clock::now() < until) heartbeat.beat();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}
