#pragma once
// The DDS options every cell process takes: --domain N (required), --all-interfaces (the
// deployment file's `localhost_only: false`; without it, loopback only) or --interface IP
// and --peer IP (its `network:`), --discovery-server IP:PORT (its `discovery:`; repeated for
// each of the cell's servers), and --security DIR with --identity NAME (its `security: DIR`;
// docs/security.md).

#include <CLI/CLI.hpp>

#include "services/blocks/sample_checks.hpp"
#include "services/node/gripper.hpp"
#include "services/dds/participant.hpp"

namespace dds {

// `all_interfaces` must outlive parsing; apply it with apply_interfaces() afterwards.
inline void add_dds_options(CLI::App& app, ParticipantSettings& settings, bool& all_interfaces) {
  app.add_option("--domain", settings.domain_id, "DDS domain id")->required()->check(CLI::Range(0, 232));
  app.add_flag("--all-interfaces", all_interfaces, "Use every network interface, not only loopback");
  app.add_option("--interface", settings.interfaces, "Use this IPv4 address of the host (repeat for more), not loopback");
  app.add_option("--peer", settings.peers, "Look for participants at this IPv4 address too (another host; repeat)");
  app.add_option("--discovery-server", settings.discovery.servers,
                 "Find the others through this discovery server, IP:PORT (repeat for each; default: simple discovery)")
      ->check(server_address_problem);
  app.add_option("--security", settings.security.dir, "DDS-Security: the folder `cellctl pki init` wrote (default: off)");
  app.add_option("--identity", settings.security.identity,
                 "DDS-Security: the identity under DIR/identities (default: the process's name)");
}

// --cell-bounds XMIN YMIN ZMIN XMAX YMAX ZMAX: the box every commanded position lies in.
// `values` must outlive parsing; apply it with apply_bounds() afterwards.
inline void add_bounds_option(CLI::App& app, std::vector<double>& values) {
  app.add_option("--cell-bounds", values, "The cell's box, m: XMIN YMIN ZMIN XMAX YMAX ZMAX (default: 50 m around 0)")
      ->expected(6);
}

// --state-dir DIR: the folder of the cell's durable state (docs/durable-state.md).
inline void add_state_option(CLI::App& app, std::string& state_dir) {
  app.add_option("--state-dir", state_dir, "Folder of the cell's database (default: state kept in memory only)");
}

// --gripper-finger-length M, ...: the arm's gripper (deployment key `gripper:`).
inline void add_gripper_options(CLI::App& app, fb::GripperGeometry& gripper) {
  for (const auto& [name, size] : fb::gripper_sizes()) {
    app.add_option(fb::gripper_option(name), gripper.*size, "The gripper's " + name + ", m (services/node/gripper.hpp)")
        ->check(CLI::PositiveNumber);
  }
}

inline fb::CellBounds apply_bounds(const std::vector<double>& values) {
  fb::CellBounds b;
  if (values.size() != 6) return b;
  for (int i = 0; i < 3; ++i) {
    if (!(values[i] < values[i + 3])) throw CLI::ValidationError("--cell-bounds", "each minimum must be below its maximum");
    b.min[i] = values[i];
    b.max[i] = values[i + 3];
  }
  return b;
}

inline void apply_interfaces(ParticipantSettings& settings, bool all_interfaces) {
  settings.localhost_only = !all_interfaces && settings.interfaces.empty();
}

}  // namespace dds
