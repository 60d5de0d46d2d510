// A cell process whose teardown hangs: it runs on services::run_until_signalled() and, asked
// to stop, never returns (as a Fast DDS deletion that deadlocks would). For the test that a
// stopped process ends within services::kStopLimit however its end goes.

#include <chrono>
#include <iostream>
#include <thread>

#include "services/node/run.hpp"

int main() {
  const std::atomic<bool>& running = services::run_until_signalled();
  std::cout << "running" << std::endl;
  while (running) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::cout << "asked to stop; hanging" << std::endl;
  for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
}
