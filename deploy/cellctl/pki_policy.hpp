#pragma once
// What each identity of a cell may publish and read (docs/security.md): the DDS-Security
// governance of the cell's domain and one permissions grant per identity, from the cell's
// deployment file. Topic names as in docs/topics.md.

#include <string>
#include <vector>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/pki.hpp"

namespace cellctl::pki {

struct Grant {
  std::string identity;  // the certificate's CN and its folder under DIR/identities
  // cell-sim, station, mobile-robot, buffer, twin, cellctl, order-desk, client; and two that
  // never join DDS (no topic): dashboard (the TLS server of cellctl up's page) and operator
  // (a person at the dashboard, by a client certificate)
  std::string role;
  std::vector<std::string> own_partitions;  // the ids it writes its capability and command events as
  std::vector<std::string> publish, subscribe;
  // Besides the owned topics (dds::owned_topic), the topics in partitions: written in its own
  // ones only, read in every one. A robot's gives to buffers; a buffer's commands, which it
  // takes from the robot they name alone.
  std::vector<std::string> as_itself = {};
  // A TLS server's: the names its certificate is valid for (subjectAltName).
  std::vector<std::string> tls_names = {};
};

// One per process of the cell (cell-sim, each station, robot and buffer), one per twin that
// may run at once (twin-1 .. twin-N, the file's twin_identities), one for cellctl, the operator's observer, one for cellctl up ("order-desk"),
// one per client of the file's `clients:`, the dashboard's server ("dashboard": 127.0.0.1,
// localhost and the file's `dashboard:` address) and one per operator of the file's `operators:`.
std::vector<Grant> cell_grants(const CellConfig& cell);

// Authenticated participants only; discovery, liveliness and every topic's data encrypted;
// read and write access control on every topic.
std::string governance_xml(int domain);

std::string permissions_xml(const Grant& grant, int domain, const Validity& validity);

}  // namespace cellctl::pki
