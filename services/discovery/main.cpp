// discovery-server: one of the cell's DDS discovery servers (Fast DDS's Discovery Server).
// The cell's processes announce themselves to the servers only and learn from them whom to
// talk to, so discovery traffic grows with the participants, not with their square.
//   discovery-server --domain 42 --discovery-server 127.0.0.1:11853 --serve 0

#include <atomic>
#include <chrono>
#include <iostream>
#include <thread>

#include <CLI/CLI.hpp>

#include "services/dds/cli_options.hpp"
#include "services/node/run.hpp"

int main(int argc, char** argv) {
  CLI::App app{"discovery-server: a DDS discovery server of the assembly cell"};
  dds::ParticipantSettings settings;
  bool all_interfaces = false;
  dds::add_dds_options(app, settings, all_interfaces);
  app.add_option("--serve", settings.discovery.serve,
                 "Which of the --discovery-server addresses this process is (0 for the first)")
      ->required()
      ->check(CLI::NonNegativeNumber);
  try {
    app.parse(argc, argv);
    dds::apply_interfaces(settings, all_interfaces);
    if (settings.discovery.serve >= static_cast<int>(settings.discovery.servers.size())) {
      throw CLI::ValidationError("--serve", "there are only " + std::to_string(settings.discovery.servers.size()) +
                                                " --discovery-server addresses");
    }
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  const std::atomic<bool>& running = services::run_until_signalled();
  const std::string name = "discovery-" + std::to_string(settings.discovery.serve);
  if (settings.security.identity.empty()) settings.security.identity = "discovery";
  try {
    const dds::ParticipantPtr participant = dds::make_participant(name, settings);
    std::cout << "discovery server " << settings.discovery.serve << " ready at "
              << settings.discovery.servers[settings.discovery.serve] << " on domain " << settings.domain_id << std::endl;
    while (running) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  } catch (const std::exception& e) {
    std::cerr << "error: " << name << ": " << e.what() << '\n';
    return 1;
  }
  return 0;
}
