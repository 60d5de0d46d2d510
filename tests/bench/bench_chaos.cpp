// The full chaos run of the durable-state issue: 10 orders on the two-station cell, 20 kills
// every 2-5 s (a twin and cell-sim first, then any resource, cell-sim, a twin, and once
// cellctl up). Prints the recovery times (p50, max), the orders assembled and failed with
// their reasons, and the checks.
// Run: build/release/bin/bench_chaos [--orders 10] [--kills 20] [--seed 1] [--domain 209]
//      [--real-time-factor 10]

#include <algorithm>
#include <iostream>

#include "tests/support/chaos.hpp"

int main(int argc, char** argv) {
  test::ChaosOptions o;
  o.cell = std::string(DEPLOY_CELLS) + "/two-stations.yaml";
  o.domain = 209;
  o.first_victims = {"twin", "cell-sim"};  // as the CI test: a seed's random picks may miss them
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--orders") o.orders = std::stoi(value);
    if (key == "--kills") o.kills = std::stoi(value);
    if (key == "--seed") o.seed = static_cast<unsigned>(std::stoul(value));
    if (key == "--domain") o.domain = std::stoi(value);
    if (key == "--real-time-factor") o.real_time_factor = value;
  }
  o.dir = std::filesystem::temp_directory_path() / ("bench-chaos-" + std::to_string(::getpid()));
  std::filesystem::create_directories(o.dir);
  o.log = [](const std::string& line) { std::cout << "kill " << line << std::endl; };
  const test::ChaosResult r = test::run_chaos(o);

  std::vector<double> rec = r.recovery_s;
  std::sort(rec.begin(), rec.end());
  std::cout << "\norders: " << r.assembled << " assembled, " << r.failed << " failed, " << r.unfinished << " unfinished\n";
  for (const auto& f : r.failures) std::cout << "  " << f << '\n';
  std::cout << "recovery (kill -> process back and the cell moving again): " << rec.size() << " kills measured, "
            << r.not_measured << " with no order left to move";
  if (!rec.empty()) std::cout << "; p50 " << rec[rec.size() / 2] << " s, max " << rec.back() << " s";
  std::cout << "\nconservation: " << r.conservation_checks << " checks, " << r.conservation_violations.size()
            << " violations\n";
  for (const auto& v : r.conservation_violations) std::cout << "  " << v << '\n';
  std::cout << "holds left: " << r.holds_left << "; integrity_check: " << r.integrity << "; down: "
            << (r.down_ok ? "ok" : "FAILED") << "; processes left: " << r.processes_left.size() << '\n';
  for (const auto& p : r.processes_left) std::cout << "  " << p << '\n';
  std::cout << "state and logs: " << o.dir.string() << '\n';
  std::cout << "kills: " << r.kills.size() << " of " << o.kills << '\n';
  const bool ok = static_cast<int>(r.kills.size()) == o.kills && r.unfinished == 0 && r.conservation_violations.empty() && r.holds_left == 0 && r.down_ok &&
                  r.processes_left.empty() && r.integrity == "ok";
  return ok ? 0 : 1;
}
