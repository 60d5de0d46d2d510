// buffer: one part buffer of the cell. Holds counts of part types, gives one part per
// "give" command, publishes its capability (with its stock) until it is stopped.
//   buffer --id buffer-1 --domain 42 --stock SquarePeg=2 --stock RoundPeg=4

#include <atomic>
#include <iostream>

#include <CLI/CLI.hpp>

#include "services/buffer/buffer_service.hpp"
#include "services/dds/cli_options.hpp"
#include "services/node/run.hpp"

int main(int argc, char** argv) {
  CLI::App app{"buffer: a part buffer of the assembly cell"};
  services::BufferConfig config;
  std::vector<std::string> stock;
  app.add_option("--id", config.node.id, "Resource id")->required();
  bool all_interfaces = false;
  dds::add_dds_options(app, config.dds, all_interfaces);
  app.add_option("--stock", stock, "TYPE=COUNT, repeatable");
  app.add_option("--position", config.node.position, "Where it stands: x y z, m");
  app.add_option("--lease", config.node.liveliness_lease_s, "Liveliness lease of the capability, s");
  dds::add_state_option(app, config.node.state_dir);
  try {
    app.parse(argc, argv);
    dds::apply_interfaces(config.dds, all_interfaces);
    for (const auto& s : stock) {
      const auto eq = s.find('=');
      if (eq == std::string::npos) throw CLI::ValidationError("--stock", "expected TYPE=COUNT, got " + s);
      config.stock[s.substr(0, eq)] = std::stoi(s.substr(eq + 1));
    }
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const std::exception& e) {
    std::cerr << "error: --stock: " << e.what() << '\n';
    return 2;
  }
  const std::atomic<bool>& running = services::run_until_signalled();
  try {
    services::BufferService service(config);
    std::cout << "buffer " << config.node.id << " ready on domain " << config.dds.domain_id << std::endl;
    service.run(running);
  } catch (const std::exception& e) {
    std::cerr << "error: buffer " << config.node.id << ": " << e.what() << '\n';
    return 1;
  }
  return 0;
}
