// Quotes that come true: on cells generated at random (one or two stations with arms of their
// own speeds, docks, robots, buffer places, rates), what `cellctl quote` promises for the
// Cranfield product against what the same cell then does (`cellctl run`, its events: the
// physical span from the first command to the last), and which of two cells it marks best.
// It fails a quote off by its order of magnitude anywhere; the goal (within 10 %, the marks
// right) is measured on a quiet machine by tests/bench/bench_quotes.sh, which runs it.
// AGILE_CELL_QUOTE_PAIRS=N runs N pairs of cells (default 1), AGILE_CELL_QUOTE_FACTOR=F at F
// times real time (default 2; tests/bench/bench_quotes.sh: 10 pairs at 8).

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "tests/support/cell_test.hpp"
#include "tests/support/domains.hpp"

namespace domains = test::domains;

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// A cell of one or two stations (tables 1 m across, 2.2 m or more apart), robots waiting
// beside them, two buffers farther out; speeds and rates drawn from what real cells have. At
// a low real-time factor the cell's messages (3.5 ms of wall time a command on a quiet
// machine, 10 ms beside `ctest -j 4` and a compiler on 2 cores) stay a small part of the sim
// time, as in a physical cell: a quote counts them as measured on a quiet machine.
std::string random_cell(std::mt19937& random, int domain, double factor) {
  const auto between = [&random](double low, double high) { return std::uniform_real_distribution<double>(low, high)(random); };
  std::ostringstream yaml;
  yaml << "domain: " << domain << "\nreal_time_factor: " << factor << "\nliveliness_lease: 5.0\nlocalhost_only: true\n"
       << "clients: [oem-a]\nsetup_cost: 40\nstations:\n";
  const int stations = 1 + static_cast<int>(random() % 2);
  double z = 0;
  for (int s = 1; s <= stations; ++s) {
    const double x = between(-0.5, 0.5);
    yaml << "  - id: station-" << s << "\n    arm: arm-" << s << "\n    position: [" << x << ", 0, " << z << "]\n"
         << "    dock: [" << x + between(0.45, 0.7) << ", 0, " << z + between(-0.3, 0.3) << "]\n"
         << "    table: [1.0, 0.025, 1.0]\n    arm_speed: " << between(0.12, 0.5)
         << "\n    arm_angular_speed: " << between(0.5, 2.0) << "\n    cost_per_hour: " << between(50, 300) << "\n";
    z += between(2.2, 3.2);
  }
  const double far = z - 1;  // the last station's z
  yaml << "mobile_robots:\n";
  const int robots = 1 + static_cast<int>(random() % 2);
  for (int r = 1; r <= robots; ++r) {
    yaml << "  - id: mobile-robot-" << r << "\n    home: [" << between(1.7, 1.9) << ", 0, " << between(-0.5, far) << "]\n"
         << "    speed: " << between(0.6, 2.0) << "\n    cost_per_hour: " << between(20, 80) << "\n";
  }
  const double first = between(-1.5, far);
  yaml << "buffers:\n  - id: buffer-1\n    position: [" << between(2.4, 3.5) << ", 0, " << first << "]\n"
       << "    stock: {FaceplateBack: 5, FaceplateFront: 5, Shaft: 5, Pendulum: 5, Separator: 5}\n"
       << "  - id: buffer-2\n    position: [" << between(2.4, 3.5) << ", 0, " << first + between(1.2, 2.5) << "]\n"
       << "    stock: {SquarePeg: 20, RoundPeg: 20}\n";
  return yaml.str();
}

struct Executed {
  double span = 0;   // s of sim time, the first physical command to the last
  double robot = 0;  // s the robot drove
};

Executed executed(const fs::path& events) {
  std::ifstream in(events);
  double first = INFINITY, last = -INFINITY;
  Executed e;
  for (std::string line; std::getline(in, line);) {
    const auto event = nlohmann::json::parse(line);
    if (event.value("part", "").find("/virtual/") != std::string::npos) continue;
    first = std::min(first, event["t"].get<double>());
    last = std::max(last, event["t"].get<double>());
    if (event["event"] == "delivered") e.robot += event["duration"].get<double>();
  }
  e.span = last - first;
  return e;
}

}  // namespace

TEST_CASE("quotes come true: on generated cells each quote is near its physical span (the bench: within 10 %), and a clear best is marked",
          "[process][quote]") {
  test::clean_stale_dds_segments();
  const char* pairs_env = std::getenv("AGILE_CELL_QUOTE_PAIRS");
  const int pairs = pairs_env ? std::max(1, std::atoi(pairs_env)) : 1;
  const char* factor_env = std::getenv("AGILE_CELL_QUOTE_FACTOR");
  const double factor = factor_env ? std::clamp(std::atof(factor_env), 1.0, 50.0) : 2.0;
  const std::string product = std::string(PRODUCTS_DIR) + "/cranfield/cranfield.aml";
  for (int pair = 0; pair < pairs; ++pair) {
    std::mt19937 random(7919 * (pair + 1));
    const fs::path dir = test::scratch("quote-accuracy-" + std::to_string(pair));
    const std::vector<std::string> names{"a", "b"};
    const std::vector<int> cell_domains{domains::kQuoteAccuracyA, domains::kQuoteAccuracyB};
    std::vector<fs::path> files;
    for (std::size_t c = 0; c < 2; ++c) {
      files.push_back(dir / (names[c] + ".yaml"));
      std::ofstream(files[c]) << random_cell(random, cell_domains[c], factor);
    }
    INFO("pair " << pair << ": " << test::read_text(files[0]) << test::read_text(files[1]));

    // Quoted by both cells at once, each idle.
    {
      std::vector<std::unique_ptr<test::ChildProcess>> ups;
      for (std::size_t c = 0; c < 2; ++c) {
        ups.push_back(std::make_unique<test::ChildProcess>(
            std::vector<std::string>{CELLCTL_EXE, "up", "--cell", files[c].string(), "--state-dir",
                                     (dir / ("state-quote-" + names[c])).string()},
            (dir / ("up-" + names[c] + ".log")).string()));
      }
      for (const auto& name : names) REQUIRE(test::appears(dir / ("up-" + name + ".log"), "cell up on domain", 60s));
      CHECK(test::cellctl({"quote", product, "--client", "oem-a", "--cell", files[0].string(), "--cell", files[1].string(),
                           "--out", (dir / "quotes").string()},
                          dir / "quote.log", 180s) == 0);
      for (std::size_t c = 0; c < 2; ++c) {
        CHECK(test::cellctl({"down", "--domain", std::to_string(cell_domains[c])}, dir / ("down-" + names[c] + ".log"), 30s) == 0);
        CHECK(ups[c]->wait_for_exit(20s) == 0);
      }
    }
    INFO(test::read_text(dir / "quote.log"));
    const auto quotes = nlohmann::json::parse(std::ifstream(dir / "quotes" / "quotes.json"));

    // Then each cell builds it.
    std::vector<Executed> done;
    std::vector<double> cost;
    for (std::size_t c = 0; c < 2; ++c) {
      const fs::path events = dir / ("events-" + names[c] + ".jsonl");
      REQUIRE(test::cellctl({"run", "--cell", files[c].string(), product, "--events", events.string(), "--out",
                             (dir / ("run-" + names[c])).string(), "--state-dir", (dir / ("state-run-" + names[c])).string()},
                            dir / ("run-" + names[c] + ".log"), 300s) == 0);
      done.push_back(executed(events));
      const auto& quote = quotes["cells"][c]["quote"];
      REQUIRE(quote["feasible"] == true);
      const double promised = quote["time_s"]["makespan"].get<double>();
      std::ostringstream line;
      line << "quote accuracy: pair " << pair << " cell " << names[c] << " quoted " << promised << " s executed "
           << done[c].span << " s ratio " << promised / done[c].span;
      std::cout << line.str() << std::endl;  // tests/bench/bench_quotes.sh gathers these
      INFO(line.str());
      // The 10 % goal is bench_quotes.sh's, on a quiet machine: here, beside other tests on 2
      // cores, a loaded host stalls the cell while its sim clock runs on (every process of a
      // cell stalled 3 s of wall time, 6 s at 2x: 0.62). What fails anywhere is a model off by
      // its order of magnitude, as the old formula's 4.2 times.
      CHECK(promised / done[c].span >= 0.4);
      CHECK(promised / done[c].span <= 2.5);
      // What the order cost at the cell's rates, from what it did: the station for the span,
      // the robot for its drives.
      const auto& rates = quote["cost"];
      const double station_rate = rates["station"].get<double>() / quote["time_s"]["station"].get<double>();
      const double robot_rate = rates["robot"].get<double>() / quote["time_s"]["robot"].get<double>();
      cost.push_back(rates["setup"].get<double>() + done[c].span * station_rate + done[c].robot * robot_rate);
    }
    // The marks: said wherever the two differ by more than the quotes' error (the bench counts
    // them); checked where a stall of one cell's run cannot turn them (by half).
    const auto best = [&names](const std::vector<double>& by) { return by[0] < by[1] ? names[0] : names[1]; };
    const auto marked = [&](const char* what, const std::vector<double>& by) {
      const double apart = std::abs(by[0] - by[1]) / std::max(by[0], by[1]);
      if (apart <= 0.1) return;  // too close to call
      const bool right = quotes[std::string("best_") + what] == best(by);
      std::cout << "quote accuracy: pair " << pair << " best by " << what << (right ? " right" : " wrong") << std::endl;
      if (apart > 0.5) CHECK(right);
    };
    marked("time", {done[0].span, done[1].span});
    marked("cost", cost);
  }
}
