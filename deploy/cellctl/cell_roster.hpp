#pragma once
// The cell's roster (idl/roster.idl): every resource of the deployment file with its kind,
// published on `cell/roster` while cellctl up or run lives, so that a twin can name a
// resource of the cell it never heard (services/blocks/negotiator.hpp).

#include <memory>

#include "deploy/cellctl/cell_config.hpp"
#include "roster.h"
#include "rosterPubSubTypes.h"
#include "services/dds/endpoints.hpp"

namespace cellctl {

cell::CellRoster roster_of(const CellConfig& cell);

class RosterWriter {
 public:
  RosterWriter(const dds::ParticipantPtr& participant, const CellConfig& cell);

 private:
  dds::Writer<cell::CellRoster, cell::CellRosterPubSubType> writer_;
};

}  // namespace cellctl
