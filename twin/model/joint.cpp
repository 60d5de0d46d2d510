#include "twin/model/joint.hpp"

#include <array>
#include <utility>

namespace twin {
namespace {

constexpr std::array<std::pair<Joint::Kind, const char*>, 7> kNames{{{Joint::Kind::contact, "contact"},
                                                                     {Joint::Kind::screw, "screw"},
                                                                     {Joint::Kind::press_fit, "press-fit"},
                                                                     {Joint::Kind::snap, "snap"},
                                                                     {Joint::Kind::studs, "studs"},
                                                                     {Joint::Kind::glue, "glue"},
                                                                     {Joint::Kind::weld, "weld"}}};

}  // namespace

std::optional<Joint::Kind> joint_kind(const std::string& name) {
  for (const auto& [kind, text] : kNames) {
    if (name == text) return kind;
  }
  return std::nullopt;
}

std::string joint_name(Joint::Kind kind) {
  for (const auto& [k, text] : kNames) {
    if (k == kind) return text;
  }
  return "contact";
}

std::string joint_names() {
  std::string out;
  for (const auto& [kind, text] : kNames) out += (out.empty() ? "" : ", ") + std::string(text);
  return out;
}

}  // namespace twin
