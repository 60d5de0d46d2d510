// The deployment file's `discovery:` key: which servers every participant uses, which of
// them cellctl starts, and what it refuses.

#include <algorithm>
#include <fstream>

#include <catch2/catch.hpp>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/host_limits.hpp"
#include "tests/support/scratch.hpp"

namespace {

cellctl::CellConfig cell_with(const std::string& extra) {
  const test::ScratchDir dir("cell-config");
  std::filesystem::create_directories(dir.path() / "pki");
  std::ofstream(dir.path() / "cell.yaml") << "domain: 50\n" << extra;
  return cellctl::read_cell_config(dir.path() / "cell.yaml");
}

bool starts(const std::vector<cellctl::ProcessSpec>& processes, const std::string& name) {
  return std::any_of(processes.begin(), processes.end(), [&](const cellctl::ProcessSpec& p) { return p.name == name; });
}

}  // namespace

TEST_CASE("deployment: discovery is simple by default, through servers where the file says, never with security", "[cellctl][config]") {
  const auto simple = cell_with("");
  CHECK(simple.discovery_addresses().empty());
  CHECK_FALSE(starts(cellctl::cell_processes(simple, "/bin"), "discovery-0"));

  const auto server = cell_with("discovery: server\n");
  CHECK(server.discovery_addresses() == std::vector<std::string>{"127.0.0.1:11861"});  // 11811 + domain
  const auto processes = cellctl::cell_processes(server, "/bin");
  REQUIRE(starts(processes, "discovery-0"));
  CHECK(processes.front().name == "discovery-0");  // before the others
  const auto& station = *std::find_if(processes.begin(), processes.end(), [](const auto& p) { return p.name == "station-1"; });
  CHECK(std::find(station.argv.begin(), station.argv.end(), "--discovery-server") != station.argv.end());

  // Two hosts: a server on each, numbered alike on both (sorted); this host starts its own.
  const auto two = cell_with("discovery: server\nnetwork: {interfaces: [10.0.0.2], peers: [10.0.0.1]}\n");
  CHECK(two.discovery_addresses() == std::vector<std::string>{"10.0.0.1:11861", "10.0.0.2:11861"});
  const auto here = cellctl::cell_processes(two, "/bin");
  CHECK(starts(here, "discovery-1"));
  CHECK_FALSE(starts(here, "discovery-0"));

  const auto listed = cell_with("discovery: {servers: [127.0.0.1:12001, 127.0.0.1:12002]}\n");
  CHECK(listed.discovery_addresses().size() == 2);

  CHECK_THROWS_WITH(cell_with("discovery: multicast\n"), Catch::Contains(":2: discovery is 'server', 'simple'"));
  CHECK_THROWS_WITH(cell_with("discovery: {servers: [127.0.0.1:80]}\n"),
                    Catch::Contains("the port must be a number in 1024..65535"));
  CHECK_THROWS_WITH(cell_with("discovery: {servers: [cell.local:12001]}\n"), Catch::Contains("is not an IPv4 address"));
  CHECK_THROWS_WITH(cell_with("discovery: server\nsecurity: pki\n"),
                    Catch::Contains("discovery through a server does not work with security"));
}

TEST_CASE("deployment: max_twins bounds the orders under way (16 by default), the desk takes 1000 not ended, and each process names its resources", "[cellctl][config]") {
  const auto plain = cell_with("");
  CHECK(plain.max_twins == 16);
  CHECK(plain.desk.max_orders == 1000);
  CHECK(cell_with("max_twins: 2\n").max_twins == 2);
  CHECK_THROWS_WITH(cell_with("max_twins: 0\n"), Catch::Contains(":2: max_twins must be 1..256"));
  CHECK_THROWS_WITH(cell_with("max_twins: many\n"), Catch::Contains(":2"));
  // What cellctl up's watchdog listens for in each process.
  const auto processes = cellctl::cell_processes(plain, "/bin");
  const auto station = std::find_if(processes.begin(), processes.end(), [](const auto& p) { return p.name == "station-1"; });
  REQUIRE(station != processes.end());
  CHECK(station->resources == std::vector<std::string>{"station-1", "arm-1"});
  CHECK(processes.front().name == "cell-sim");
  CHECK(processes.front().resources.empty());
}

TEST_CASE("host limits: participants for simple discovery and for Fast DDS's ports, memory, threads, open files", "[cellctl][config]") {
  const cellctl::HostLimits roomy{24000, 100000, 1024};
  const auto cell = cell_with("");  // 5 processes: cell-sim, a station, a robot, two buffers
  CHECK(cellctl::limit_problems(cell, 5, 16, roomy).empty());  // 5 + 16 + 1 standing by + cellctl = 23
  const auto crowded = cellctl::limit_problems(cell, 5, 22, roomy);
  REQUIRE(crowded.size() == 1);
  CHECK_THAT(crowded[0], Catch::Contains("29 DDS participants on this host") && Catch::Contains("discovery: server"));

  const auto server = cell_with("discovery: server\n");
  CHECK(cellctl::limit_problems(server, 6, 100, roomy).empty());
  CHECK_THAT(cellctl::limit_problems(server, 6, 110, roomy).at(0), Catch::Contains("pass the 116 Fast DDS gives ports to"));
  // The ports of the highest domain run out sooner: 7400 + 250 x 232 + 10 + 2 x id + 1 <= 65535.
  CHECK(cellctl::participant_ports(0) == 120);
  CHECK(cellctl::participant_ports(230) == 120);
  CHECK(cellctl::participant_ports(232) == 63);

  const auto small = cellctl::limit_problems(server, 6, 60, {2048, 100000, 1024});
  REQUIRE(small.size() == 1);
  CHECK_THAT(small[0], Catch::Contains("the host has 2048 MB: lower max_twins"));
  CHECK_THAT(cellctl::limit_problems(server, 6, 60, {24000, 500, 1024}).at(0), Catch::Contains("(ulimit -u)"));
  CHECK_THAT(cellctl::limit_problems(server, 6, 60, {24000, 100000, 128}).at(0), Catch::Contains("(ulimit -n)"));
}

TEST_CASE("every shipped cell fits a host of 2 cores and 8 GB with its max_twins", "[cellctl][config]") {
  for (const auto& entry : std::filesystem::directory_iterator(DEPLOY_CELLS)) {
    if (entry.path().extension() != ".yaml") continue;
    INFO(entry.path());
    const auto cell = cellctl::read_cell_config(entry.path());
    const auto processes = cellctl::cell_processes(cell, "/bin").size();
    CHECK(cellctl::limit_problems(cell, processes, static_cast<std::size_t>(cell.max_twins), {8192, 4096, 1024}).empty());
  }
}

TEST_CASE("deployment: dashboard is [ADDR:]PORT, loopback unless ADDR says, none by default", "[cellctl][config]") {
  CHECK(cell_with("").dashboard.empty());
  CHECK(cell_with("dashboard: 8080\n").dashboard == "8080");
  const auto loopback = cellctl::parse_dashboard_address("8080");
  CHECK(loopback.host == "127.0.0.1");
  CHECK(loopback.port == 8080);
  const auto any = cellctl::parse_dashboard_address("0.0.0.0:0");
  CHECK(any.host == "0.0.0.0");
  CHECK(any.port == 0);
  CHECK_THROWS_WITH(cell_with("dashboard: 70000\n"), Catch::Contains(":2: dashboard: '70000' is not [ADDR:]PORT"));
  CHECK_THROWS_WITH(cell_with("dashboard: web\n"), Catch::Contains(":2"));
  CHECK_THROWS_AS(cellctl::parse_dashboard_address(":8080"), cellctl::ConfigError);
}

TEST_CASE("deployment: operators are names of their own (their certificates' too), none by default", "[cellctl][config]") {
  CHECK(cell_with("").operators.empty());
  CHECK(cell_with("operators: [alice, bob]\n").operators == std::vector<std::string>{"alice", "bob"});
  CHECK_THROWS_WITH(cell_with("operators: [Alice]\n"), Catch::Contains(":2: a name in operators is 1 to 64 of a-z"));
  CHECK_THROWS_WITH(cell_with("clients: [alice]\noperators: [alice]\n"),
                    Catch::Contains("'alice' of operators has the name of a resource, of another client or operator"));
  for (const std::string taken : {"dashboard", "order-desk", "twin-3", "station-1"}) {
    CHECK_THROWS_WITH(cell_with("operators: [" + taken + "]\n"), Catch::Contains("has the name of"));
  }
}

TEST_CASE("deployment: a key given twice is refused with both lines, not the second dropped", "[cellctl][config]") {
  CHECK_THROWS_WITH(cell_with("gripper:\n  max_opening: 0.1\ngripper:\n  max_opening: 0.3\n"),
                    Catch::Contains(":4: the key 'gripper' is given twice (first on line 2)"));
  CHECK_THROWS_WITH(cell_with("gripper:\n  max_opening: 0.1\n  max_opening: 0.3\n"),
                    Catch::Contains(":4: the key 'max_opening' is given twice (first on line 3)"));
}
