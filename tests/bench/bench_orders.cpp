// Benchmark of many orders on a cell: `cellctl run` of N mixed orders (Lego towers and
// Cranfield pendulums in turn) on a deployment file, and from its event log and its table:
//  - the makespan in sim seconds (first order's start to last order's end);
//  - the lower bound: the arms' work shared by all arms at once, or the longest single
//    order, whichever is larger. An arm's work is its busy time times its speed (metres:
//    arms of different speeds, as in mixed-stations.yaml, turn at the same angular speed),
//    and all arms together do sum(speed) metres a second: for equal arms, the busy time over
//    the number of stations. A single order's length is its own work: from its first command
//    to its last, plus the time before any order could start physical work (planning and
//    virtual assembly);
//  - each arm's idle time at a change of order (its last command for one order to its first
//    for the next);
//  - the peak RSS of every process (cellctl's table: cell processes, and each twin).
// BENCH_KEEP=1 keeps the event log and the twins' output in the temporary directory.
// Run: build/release/bin/bench_orders [--orders 10] [--cell deploy/cells/two-stations.yaml]
//      [--domain 201] [--real-time-factor 20]

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <numeric>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include "tests/support/child_process.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct Span {
  double start = 1e300, end = -1e300;
  void add(double t) {
    start = std::min(start, t);
    end = std::max(end, t);
  }
};

// Arm id -> its speed (m/s), from the deployment file.
std::map<std::string, double> arm_speeds(const std::string& cell_file) {
  const YAML::Node cell = YAML::LoadFile(cell_file);
  std::map<std::string, double> out;
  const auto add = [&out](const YAML::Node& station) {
    out[station["arm"] ? station["arm"].as<std::string>() : "arm-1"] =
        station["arm_speed"] ? station["arm_speed"].as<double>() : 0.25;
  };
  if (cell["stations"]) {
    for (const auto& station : cell["stations"]) add(station);
  } else {
    add(cell["station"] ? cell["station"] : YAML::Node());
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  int orders = 10, domain = 201;
  std::string cell = std::string(DEPLOY_CELLS) + "/default.yaml", factor = "20";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--orders") orders = std::stoi(argv[i + 1]);
    if (key == "--cell") cell = argv[i + 1];
    if (key == "--domain") domain = std::stoi(argv[i + 1]);
    if (key == "--real-time-factor") factor = argv[i + 1];
  }
  const fs::path dir = fs::temp_directory_path() / ("bench-orders-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::vector<std::string> args{CELLCTL_EXE, "run", "--cell", cell, "--domain", std::to_string(domain),
                                "--real-time-factor", factor, "--events", (dir / "events.jsonl").string(),
                                "--out", (dir / "out").string()};
  for (int i = 0; i < orders; ++i) {
    args.push_back(std::string(PRODUCTS_DIR) + (i % 2 == 0 ? "/lego-tower/lego-tower.aml" : "/cranfield/cranfield.aml"));
  }
  test::clean_stale_dds_segments();
  const auto started = std::chrono::steady_clock::now();
  test::ChildProcess run(args, (dir / "cellctl.log").string());
  const int code = run.wait_for_exit(std::chrono::minutes(20));
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  std::ifstream log_file(dir / "cellctl.log");
  std::stringstream log;
  log << log_file.rdbuf();
  if (code != 0) {
    std::cerr << log.str() << "\nerror: cellctl run exited " << code << '\n';
    return 1;
  }

  // The arms' busy time: every arm command from accepted to its end, physical parts only.
  std::map<std::string, Span> commands, of_order;
  std::map<std::string, std::string> arm_of, order_of;
  std::ifstream events(dir / "events.jsonl");
  for (std::string line; std::getline(events, line);) {
    const json e = json::parse(line);
    const double t = e["t"];
    of_order[e["order"]].add(t);
    const std::string resource = e["resource"];
    if (resource.rfind("arm-", 0) == 0) {
      commands[e["command"]].add(t);
      arm_of[e["command"]] = resource;
      order_of[e["command"]] = e["order"];
    }
  }
  const std::map<std::string, double> speeds = arm_speeds(cell);
  double arm_busy = 0, arm_work = 0, all_speeds = 0;
  for (const auto& [id, span] : commands) {
    arm_busy += span.end - span.start;
    arm_work += (span.end - span.start) * speeds.at(arm_of[id]);
  }
  for (const auto& [arm, speed] : speeds) all_speeds += speed;

  // Where each arm's time went: its first command, its last, the gaps between commands, and
  // those at a change of order.
  struct Command {
    Span span;
    std::string order;
  };
  std::map<std::string, std::vector<Command>> of_arm;
  for (const auto& [id, span] : commands) of_arm[arm_of[id]].push_back({span, order_of[id]});
  std::ostringstream arms;
  std::vector<double> changes;
  for (auto& [arm, done] : of_arm) {
    std::sort(done.begin(), done.end(), [](const Command& a, const Command& b) { return a.span.start < b.span.start; });
    double busy = 0, idle = 0, long_idle = 0, end = done.front().span.start;
    int long_gaps = 0, orders_here = 1;
    for (std::size_t i = 0; i < done.size(); ++i) {
      const Span& s = done[i].span;
      busy += s.end - s.start;
      const double gap = std::max(0.0, s.start - end);
      idle += gap;
      if (gap > 1.0) ++long_gaps, long_idle += gap;
      if (i > 0 && done[i].order != done[i - 1].order) ++orders_here, changes.push_back(gap);
      end = std::max(end, s.end);
    }
    arms << "  " << arm << " (" << speeds.at(arm) << " m/s): " << orders_here << " orders, first command "
         << done.front().span.start << ", last end " << end << ", busy " << busy << ", idle between " << idle << " ("
         << long_gaps << " gaps over 1 s: " << long_idle << ")\n";
  }
  if (!changes.empty()) {
    arms << "  idle at a change of order: mean " << std::accumulate(changes.begin(), changes.end(), 0.0) / changes.size()
         << ", max " << *std::max_element(changes.begin(), changes.end()) << " sim s (" << changes.size() << " changes)\n";
  }

  // Sim start and end per order, and the makespan, from cellctl's table.
  const std::regex row(R"(^(\S+)\s+\S+\.aml\s+assembled\s+([0-9.]+)\s+([0-9.]+)\s+([0-9]+))");
  const std::regex makespan_line(R"(makespan ([0-9.]+) sim s)");
  const std::regex rss_row(R"(^(cell-sim|station-\d+|mobile-robot-\d+|buffer-\d+)\s+([0-9]+)\s*$)");
  double makespan = 0, first_start = 1e300, before_work = 1e300, longest = 0, twin_rss = 0;
  std::map<std::string, double> rss;
  std::istringstream lines(log.str());
  for (std::string l; std::getline(lines, l);) {
    std::smatch m;
    if (std::regex_search(l, m, row)) {
      first_start = std::min(first_start, std::stod(m[2]));
      twin_rss = std::max(twin_rss, std::stod(m[4]));
    } else if (std::regex_search(l, m, makespan_line)) {
      makespan = std::stod(m[1]);
    } else if (std::regex_search(l, m, rss_row)) {
      rss[m[1]] = std::stod(m[2]);
    }
  }
  for (const auto& [order, span] : of_order) before_work = std::min(before_work, span.start - first_start);
  for (const auto& [order, span] : of_order) longest = std::max(longest, span.end - span.start + before_work);
  const std::size_t stations = speeds.size();
  const double bound = std::max(arm_work / all_speeds, longest);

  std::cout << "cell " << fs::path(cell).filename().string() << " (" << stations << " stations), " << orders
            << " orders, real-time factor " << factor << ", " << static_cast<int>(wall) << " s wall\n"
            << "  makespan " << makespan << " sim s\n"
            << "  arm busy " << arm_busy << " sim s; shared by the " << stations << " arms: " << arm_work / all_speeds << "\n"
            << "  longest single order " << longest << " sim s (of it " << before_work << " before any physical work)\n"
            << arms.str() << "  lower bound " << bound << " sim s; makespan / bound " << makespan / bound << "\n"
            << "  peak RSS MB: twin (largest) " << twin_rss;
  for (const auto& [name, mb] : rss) std::cout << ", " << name << " " << mb;
  std::cout << std::endl;
  if (std::getenv("BENCH_KEEP") == nullptr) fs::remove_all(dir);
  else std::cout << "  kept " << dir.string() << std::endl;
  return 0;
}
