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
  std::string role;      // cell-sim, station, mobile-robot, buffer, twin, cellctl, order-desk, client
  std::vector<std::string> own_partitions;  // the ids it writes its capability and command events as
  std::vector<std::string> publish, subscribe;
  // Besides the owned topics (dds::owned_topic), the topics in partitions: written in its own
  // ones only, read in every one. A robot's gives to buffers; a buffer's commands, which it
  // takes from the robot they name alone.
  std::vector<std::string> as_itself = {};
};

// One per process of the cell (cell-sim, each station, robot and buffer), one per twin that
// may run at once (twin-1 .. twin-N, the file's twin_identities), one for cellctl, the operator's observer, one for cellctl up ("order-desk"), and
// one per client of the file's `clients:`.
std::vector<Grant> cell_grants(const CellConfig& cell);

// Authenticated participants only; discovery, liveliness and every topic's data encrypted;
// read and write access control on every topic.
std::string governance_xml(int domain);

std::string permissions_xml(const Grant& grant, int domain, const Validity& validity);

}  // namespace cellctl::pki
