// The deployment file's `discovery:` key: which servers every participant uses, which of
// them cellctl starts, and what it refuses.

#include <algorithm>
#include <fstream>

#include <catch2/catch.hpp>

#include "deploy/cellctl/cell_config.hpp"
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
