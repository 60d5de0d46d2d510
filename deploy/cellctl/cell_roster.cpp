#include "deploy/cellctl/cell_roster.hpp"

namespace cellctl {

cell::CellRoster roster_of(const CellConfig& c) {
  cell::CellRoster roster;
  roster.cell(c.file.stem().string());
  const auto add = [&roster](const std::string& id, const char* kind) {
    cell::RosterEntry e;
    e.resource_id(id);
    e.kind(kind);
    if (roster.resources().size() < 256) roster.resources().push_back(e);  // the type's bound
  };
  for (const auto& s : c.stations) {
    add(s.id, "station");
    add(s.arm, "arm");
  }
  for (const auto& r : c.robots) add(r.id, "mobile-robot");
  for (const auto& b : c.buffers) add(b.id, "buffer");
  return roster;
}

RosterWriter::RosterWriter(const dds::ParticipantPtr& participant, const CellConfig& cell)
    : writer_(participant, "cell/roster", dds::TopicKind::state) {
  writer_.write(roster_of(cell));
}

}  // namespace cellctl
