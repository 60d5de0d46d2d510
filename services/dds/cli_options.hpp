#pragma once
// The DDS options every cell process takes: --domain N (required) and --all-interfaces
// (the deployment file's `localhost_only: false`; without it, loopback only).

#include <CLI/CLI.hpp>

#include "services/dds/participant.hpp"

namespace dds {

// `all_interfaces` must outlive parsing; apply it with apply_interfaces() afterwards.
inline void add_dds_options(CLI::App& app, ParticipantSettings& settings, bool& all_interfaces) {
  app.add_option("--domain", settings.domain_id, "DDS domain id")->required()->check(CLI::Range(0, 232));
  app.add_flag("--all-interfaces", all_interfaces, "Use every network interface, not only loopback");
}

inline void apply_interfaces(ParticipantSettings& settings, bool all_interfaces) {
  settings.localhost_only = !all_interfaces;
}

}  // namespace dds
