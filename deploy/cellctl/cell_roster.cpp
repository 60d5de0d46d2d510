#include "deploy/cellctl/cell_roster.hpp"

namespace cellctl {

cell::CellRoster roster_of(const CellConfig& c, const OutOfService& out_of_service) {
  cell::CellRoster roster;
  roster.cell(c.file.stem().string());
  const auto add = [&](const std::string& id, const char* kind) {
    cell::RosterEntry e;
    e.resource_id(id);
    e.kind(kind);
    if (const auto out = out_of_service.find(id); out != out_of_service.end()) {
      e.out_of_service(out->second.substr(0, cell::Text::max_size - 1));
    }
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

RosterWriter::RosterWriter(const dds::ParticipantPtr& participant, const CellConfig& cell, OutOfService out_of_service)
    : cell_(cell), published_(std::move(out_of_service)), writer_(participant, "cell/roster", dds::TopicKind::state) {
  writer_.write(roster_of(cell_, published_));
}

void RosterWriter::update(const OutOfService& out_of_service) {
  if (out_of_service == published_) return;
  published_ = out_of_service;
  writer_.write(roster_of(cell_, published_));
}

}  // namespace cellctl
