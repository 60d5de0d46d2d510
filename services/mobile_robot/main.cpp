// mobile-robot: fetches parts from buffers to a station, one after another in the order the
// fetch commands came. Learns where buffers and stations hand parts over from their
// capabilities; asks a buffer for a part with a "give" command.
//   mobile-robot --domain 42 --id mobile-robot-1 --home 1.5 0 1.2 --speed 0.8

#include <atomic>
#include <iostream>

#include <CLI/CLI.hpp>

#include "capabilitiesPubSubTypes.h"
#include "commandsPubSubTypes.h"
#include "services/dds/cli_options.hpp"
#include "services/dds/conversions.hpp"
#include "services/dds/service_blocks.hpp"
#include "services/mobile_robot/mobile_robot_block.hpp"
#include "services/node/resource_node.hpp"
#include "services/node/run.hpp"

int main(int argc, char** argv) {
  CLI::App app{"mobile-robot: fetches parts from buffers to the station"};
  dds::ParticipantSettings dds;
  services::NodeConfig config;
  config.id = "mobile-robot-1";
  config.kind = "mobile-robot";
  config.speed = 0.8;
  config.when_busy = fb::CommandLifecycle::WhenBusy::queue;
  config.offers = {"fetch"};
  config.exclusive = false;  // hired per batch of fetches: its queue holds several orders' work
  bool all_interfaces = false;
  dds::add_dds_options(app, dds, all_interfaces);
  app.add_option("--id", config.id, "Resource id");
  app.add_option("--home", config.position, "Where it waits: x y z, m");
  app.add_option("--speed", config.speed, "m/s")->check(CLI::PositiveNumber);
  app.add_option("--lease", config.liveliness_lease_s, "Liveliness lease of the capability, s");
  dds::add_state_option(app, config.state_dir);
  CLI11_PARSE(app, argc, argv);
  dds::apply_interfaces(dds, all_interfaces);
  const std::atomic<bool>& running = services::run_until_signalled();
  try {
    auto participant = dds::make_participant(config.id, dds);
    fb::Resource resource(config.id, 1024);
    auto& robot = resource.add(std::make_unique<fb::MobileRobotBlock>(
        "robot", config.id, fb::Numbers(config.position.begin(), config.position.end()), config.speed));
    const auto estimate = [&robot](const fb::Data& call) {
      return robot.estimate(fb::split_names(fb::get_or<std::string>(call, "sources", "")),
                            fb::get_or<std::string>(call, "station", ""));
    };
    services::ResourceNode node(resource, participant, config, robot, estimate);
    auto& places = resource.add(std::make_unique<dds::SubscribeBlock<cell::Capability, cell::CapabilityPubSubType>>(
        "places", participant, "cell/capabilities", dds::TopicKind::state, [](const cell::Capability& c) {
          return fb::Data{{"resource_id", c.resource_id().to_string()}, {"dock", dds::to_numbers(c.dock())}};
        }));
    auto& give_events = resource.add(std::make_unique<dds::SubscribeBlock<cell::CommandEvent, cell::CommandEventPubSubType>>(
        "give_events", participant, "cell/command_events", dds::TopicKind::events, [](const cell::CommandEvent& e) {
          // Only answers to gives (this robot's among them), not the whole cell's traffic.
          const std::string id = e.command_id().to_string();
          if (id.size() < 5 || id.compare(id.size() - 5, 5, "/give") != 0) return fb::Data{};
          return fb::Data{{"command_id", id}, {"state", std::string(dds::state_name(e.state()))},
                          {"reason", e.reason().to_string()}};
        }));
    resource.add(std::make_unique<dds::RoutedPublishBlock<cell::Command, cell::CommandPubSubType>>(
        "gives", participant, [](const fb::Data& d) { return dds::command_topic(fb::get<std::string>(d, "resource_id")); },
        [](const fb::Data& d) { return dds::to_command(d); }, dds::owned_by({config.id}, dds::command_qos())));
    resource.connect("places", "IND", "robot", "PLACE");
    resource.connect("give_events", "IND", "robot", "GIVE_EVENT");
    resource.connect("robot", "GIVE", "gives", "REQ");
    resource.connect("robot", "PREPARE_GIVE", "gives", "PREPARE");
    node.start(std::chrono::seconds(30), &running);
    places.start();
    give_events.start();
    services::post_when_room(resource, "robot", "INIT");
    std::cout << "mobile-robot " << config.id << " ready on domain " << dds.domain_id << std::endl;
    services::run_until_stopped({&resource}, running);
  } catch (const std::exception& e) {
    std::cerr << "error: mobile-robot " << config.id << ": " << e.what() << '\n';
    return 1;
  }
  return 0;
}
