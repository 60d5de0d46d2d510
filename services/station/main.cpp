// station: the assembly station and its robot arm, two resources of one process, each with
// its own capability and event queue. The station is the place an order reserves; the arm
// grips, moves, releases, connects and disconnects parts in cell-sim.
//   station --domain 42 --id station-1 --arm-id arm-1 --position 0 0 0 --dock 0.6 0 0

#include <atomic>
#include <iostream>

#include <CLI/CLI.hpp>

#include "services/dds/cli_options.hpp"
#include "services/node/resource_node.hpp"
#include "services/node/run.hpp"
#include "services/station/arm_block.hpp"
#include "services/station/station_block.hpp"

int main(int argc, char** argv) {
  CLI::App app{"station: the assembly station and its robot arm"};
  dds::ParticipantSettings dds;
  services::NodeConfig station, arm;
  station.id = "station-1";
  station.kind = "station";
  arm.id = "arm-1";
  arm.kind = "arm";
  station.offers = {"host"};
  arm.offers = {"translate"};
  std::array<double, 3> table{1.0, 0.025, 1.0};
  fb::ArmSettings arm_settings;
  bool all_interfaces = false;
  std::vector<double> bounds;
  dds::add_dds_options(app, dds, all_interfaces);
  dds::add_bounds_option(app, bounds);
  app.add_option("--id", station.id, "Resource id of the station");
  app.add_option("--arm-id", arm.id, "Resource id of its arm");
  app.add_option("--position", station.position, "The assembly point on the table's top: x y z, m");
  app.add_option("--dock", station.dock, "Where parts are delivered: x y z, m");
  app.add_option("--table", table, "Half extents of the table, m");
  app.add_option("--arm-speed", arm_settings.speed, "m/s")->check(CLI::PositiveNumber);
  app.add_option("--arm-angular-speed", arm_settings.angular_speed, "rad/s")->check(CLI::PositiveNumber);
  dds::add_gripper_options(app, arm_settings.gripper);
  app.add_option("--lease", station.liveliness_lease_s, "Liveliness lease of the capabilities, s");
  dds::add_state_option(app, station.state_dir);
  CLI11_PARSE(app, argc, argv);
  dds::apply_interfaces(dds, all_interfaces);
  arm.position = station.position;
  arm.dock = station.dock;
  arm.speed = arm_settings.speed;
  arm.angular_speed = arm_settings.angular_speed;
  arm.liveliness_lease_s = station.liveliness_lease_s;
  arm.state_dir = station.state_dir;
  const std::atomic<bool>& running = services::run_until_signalled();
  try {
    arm.bounds = station.bounds = dds::apply_bounds(bounds);
    auto participant = dds::make_participant(station.id, dds);
    fb::Resource station_resource(station.id, 256), arm_resource(arm.id, 256);
    auto& station_block = station_resource.add(std::make_unique<fb::StationBlock>(
        "station", station.id, fb::Numbers(station.position.begin(), station.position.end()),
        fb::Numbers(table.begin(), table.end())));
    auto& arm_block = arm_resource.add(std::make_unique<fb::ArmBlock>("arm", arm.id, arm_settings));
    // Both are held by one order at a time, for as long as it says it needs them; the arm
    // only by an order that works at its station.
    // A call may name the station it wants (an order moving to a shorter queue).
    const auto hold = [&station](const fb::Data& call) {
      const std::string at = fb::get_or<std::string>(call, "station", "");
      if (!at.empty() && at != station.id && fb::get<std::string>(call, "operation") == "host") {
        return fb::Contractor::Estimate{false, "the call is for " + at, 0};
      }
      return fb::Contractor::Estimate{true, "", fb::get_or<double>(call, "duration", 0)};
    };
    const auto hold_arm = [&station, &arm, hold](const fb::Data& call) {
      const std::string at = fb::get_or<std::string>(call, "station", "");
      if (at != station.id) return fb::Contractor::Estimate{false, arm.id + " works at " + station.id + ", not " + at, 0};
      return hold(call);
    };
    services::ResourceNode station_node(station_resource, participant, station, station_block, hold);
    services::ResourceNode arm_node(arm_resource, participant, arm, arm_block, hold_arm);
    station_node.start(std::chrono::seconds(30), &running);
    arm_node.start(std::chrono::seconds(30), &running);
    services::post_when_room(station_resource, "station", "INIT");
    std::cout << "station " << station.id << " with arm " << arm.id << " ready on domain " << dds.domain_id
              << std::endl;
    services::run_until_stopped({&station_resource, &arm_resource}, running);
  } catch (const std::exception& e) {
    std::cerr << "error: station " << station.id << ": " << e.what() << '\n';
    return 1;
  }
  return 0;
}
