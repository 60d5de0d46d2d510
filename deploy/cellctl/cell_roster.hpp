#pragma once
// The cell's roster (idl/roster.idl): every resource of the deployment file with its kind and
// whether the operator took it out of service, published on `cell/roster` while cellctl up or
// run lives. A twin names a resource of the cell it never heard (services/blocks/negotiator.hpp);
// a resource out of service takes no new work (services/blocks/contractor.hpp).

#include <map>
#include <string>

#include "deploy/cellctl/cell_config.hpp"
#include "roster.h"
#include "rosterPubSubTypes.h"
#include "services/dds/endpoints.hpp"

namespace cellctl {

// Resource id -> why it is out of service.
using OutOfService = std::map<std::string, std::string>;

cell::CellRoster roster_of(const CellConfig& cell, const OutOfService& out_of_service = {});

class RosterWriter {
 public:
  RosterWriter(const dds::ParticipantPtr& participant, const CellConfig& cell, OutOfService out_of_service = {});
  // Publishes the roster again if what is out of service changed.
  void update(const OutOfService& out_of_service);

 private:
  const CellConfig& cell_;
  OutOfService published_;
  dds::Writer<cell::CellRoster, cell::CellRosterPubSubType> writer_;
};

}  // namespace cellctl
