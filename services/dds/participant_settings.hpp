#pragma once
// How a cell participant joins its domain: plain data, free of Fast DDS headers, so that a
// program that only reads a deployment (cellctl plan) need not load Fast DDS.

#include <arpa/inet.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace dds {

struct SecuritySettings {
  std::filesystem::path dir;  // empty: security off
  std::string identity;       // the folder under DIR/identities; empty: the participant's name
};

// Fast DDS's Discovery Server: participants announce themselves to the cell's servers only,
// and learn from them whom to talk to; with no servers, every participant announces itself to
// a fixed range of ports at each peer address (simple discovery, which collapses past 32
// participants on a host; docs/topics.md).
struct DiscoverySettings {
  std::vector<std::string> servers;  // "IP:PORT" each; a server's place in the list is its id
  int serve = -1;                    // this participant is servers[serve]; -1: a client of them all
  double announce_every_s = 0.5;     // how often the participant announces itself (participant.cpp)
};

// "IP:PORT" -> {IP, PORT}; throws std::invalid_argument saying what is wrong.
inline std::pair<std::string, int> server_address(const std::string& address_port) {
  const std::string bad = "discovery server '" + address_port + "': ";
  const auto colon = address_port.rfind(':');
  if (colon == std::string::npos) throw std::invalid_argument(bad + "expected IP:PORT");
  const std::string ip = address_port.substr(0, colon), digits = address_port.substr(colon + 1);
  in_addr parsed{};
  if (::inet_pton(AF_INET, ip.c_str(), &parsed) != 1) throw std::invalid_argument(bad + "'" + ip + "' is not an IPv4 address");
  const bool numeric = !digits.empty() && digits.size() <= 5 && digits.find_first_not_of("0123456789") == std::string::npos;
  const int port = numeric ? std::stoi(digits) : 0;
  if (port < 1024 || port > 65535) throw std::invalid_argument(bad + "the port must be a number in 1024..65535");
  return {ip, port};
}

// What is wrong with "IP:PORT", or "" (a command line's check).
inline std::string server_address_problem(const std::string& address_port) {
  try {
    server_address(address_port);
    return "";
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
}

struct ParticipantSettings {
  int domain_id = 0;
  bool localhost_only = true;
  SecuritySettings security;  // off unless security.dir is set (services/dds/security.hpp)
  // Without localhost_only: the host's addresses to use, and other hosts' to look for
  // participants at (unicast discovery); both empty: every interface, Fast DDS's default
  // discovery.
  std::vector<std::string> interfaces{}, peers{};
  DiscoverySettings discovery{};
};

}  // namespace dds
