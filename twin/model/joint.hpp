#pragma once
// What a link joins two parts with (docs/automationml.md, "Joints"): parts that only touch, or
// a fastening that holds them together once the cell has made it (a screw, a press fit, a
// snap, studs, glue, a weld). A fastened part no longer needs anything under it to stand.

#include <optional>
#include <string>

#include "twin/model/source_ref.hpp"

namespace twin {

struct Joint {
  enum class Kind { contact, screw, press_fit, snap, studs, glue, weld };
  Kind kind = Kind::contact;
  double pitch = 0;  // m the screw advances per turn (screw only)
  SourceRef where;   // where it is declared

  bool fastens() const { return kind != Kind::contact; }
};

// "screw", "press-fit", ...; nothing for a name that is none of them.
std::optional<Joint::Kind> joint_kind(const std::string& name);
std::string joint_name(Joint::Kind kind);
// Every name joint_kind takes, for messages: "contact, screw, press-fit, snap, studs, glue, weld".
std::string joint_names();

}  // namespace twin
