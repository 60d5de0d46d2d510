#pragma once
// How a cell participant joins its domain: plain data, free of Fast DDS headers, so that a
// program that only reads a deployment (cellctl plan) need not load Fast DDS.

#include <filesystem>
#include <string>
#include <vector>

namespace dds {

struct SecuritySettings {
  std::filesystem::path dir;  // empty: security off
  std::string identity;       // the folder under DIR/identities; empty: the participant's name
};

struct ParticipantSettings {
  int domain_id = 0;
  bool localhost_only = true;
  SecuritySettings security;  // off unless security.dir is set (services/dds/security.hpp)
  // Without localhost_only: the host's addresses to use, and other hosts' to look for
  // participants at (unicast discovery); both empty: every interface, Fast DDS's default
  // discovery.
  std::vector<std::string> interfaces{}, peers{};
};

}  // namespace dds
