#include "twin/description/automationml/caex_values.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <vector>

namespace twin::aml {

std::string normalize_id(std::string_view id) {
  if (id.size() >= 2 && id.front() == '{' && id.back() == '}') id = id.substr(1, id.size() - 2);
  std::string out(id);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return std::tolower(c); });
  return out;
}
namespace {

std::string trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r\n");
  return std::string(s.substr(first, last - first + 1));
}

double parse_number(const std::string& text, const SourceRef& where, const std::string& what) {
  const std::string t = trim(text);
  double value = 0;
  const char* begin = t.data();
  const char* end = t.data() + t.size();
  if (!t.empty() && *begin == '+') ++begin;
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  if (t.empty() || ec != std::errc() || ptr != end || !std::isfinite(value)) {
    throw DescriptionError(where, what + " '" + t + "' is not a finite number");
  }
  return value;
}

double angle_unit_scale(const std::string& unit, const SourceRef& where) {
  if (unit.empty() || unit == "deg" || unit == "degree" || unit == "°") return 1.0;
  if (unit == "rad" || unit == "radian") return 180.0 / M_PI;
  throw DescriptionError(where, "unknown angle unit '" + unit + "' (expected deg or rad)");
}

std::string unit_of(const pugi::xml_node& attribute) { return trim(attribute.attribute("Unit").value()); }

}  // namespace

std::optional<std::string> attribute_text(const pugi::xml_node& attribute) {
  if (const auto value = child(attribute, "Value")) return trim(value.text().get());
  if (const auto value = child(attribute, "DefaultValue")) return trim(value.text().get());
  return std::nullopt;
}

double length_unit_scale(const std::string& unit, const SourceRef& where) {
  static const std::map<std::string, double> scales = {
      {"", 1.0},       {"m", 1.0},        {"meter", 1.0},        {"metre", 1.0},
      {"mm", 1e-3},    {"millimeter", 1e-3}, {"millimetre", 1e-3}, {"cm", 1e-2},
      {"centimeter", 1e-2}, {"centimetre", 1e-2}, {"dm", 1e-1},     {"km", 1e3},
      {"in", 0.0254},  {"inch", 0.0254}};
  const auto it = scales.find(unit);
  if (it == scales.end()) {
    throw DescriptionError(where, "unknown length unit '" + unit + "' (expected m, cm, mm or in)");
  }
  return it->second;
}

Vec3 parse_vec3(const std::string& text, double scale, const SourceRef& where) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  while (true) {
    const auto comma = text.find(',', start);
    fields.push_back(text.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (fields.size() != 3) {
    throw DescriptionError(where, "coordinate '" + text + "' is not three numbers x,y,z");
  }
  Vec3 v;
  for (int i = 0; i < 3; ++i) v[i] = parse_number(fields[i], where, "coordinate component") * scale;
  return v;
}

Quat parse_orientation(const pugi::xml_node& attribute, const XmlFile& file) {
  const SourceRef where = file.where(attribute);
  const auto text = attribute_text(attribute);
  if (!text || text->empty()) return Quat::Identity();
  const double scale = angle_unit_scale(unit_of(attribute), where);
  return rotation_from_xyz_degrees(parse_vec3(*text, scale, where));
}

Frame parse_frame(const pugi::xml_node& frame_attribute, const XmlFile& file) {
  const std::string frame_unit = unit_of(frame_attribute);
  Vec3 position = Vec3::Zero();
  Vec3 angles = Vec3::Zero();
  for_each_child(frame_attribute, "Attribute", [&](const pugi::xml_node& component) {
    const std::string name = component.attribute("Name").value();
    static const std::map<std::string, int> axes = {{"x", 0}, {"y", 1}, {"z", 2},
                                                    {"rx", 3}, {"ry", 4}, {"rz", 5}};
    const auto axis = axes.find(name);
    if (axis == axes.end()) return;
    const SourceRef where = file.where(component);
    const auto text = attribute_text(component);
    if (!text || text->empty()) return;
    const std::string unit = unit_of(component).empty() ? frame_unit : unit_of(component);
    if (axis->second < 3) {
      position[axis->second] =
          parse_number(*text, where, "Frame " + name) * length_unit_scale(unit, where);
    } else {
      // A Frame's Unit, when on the Frame itself, names the length unit, not the angles'.
      const std::string angle_unit = unit_of(component);
      angles[axis->second - 3] =
          parse_number(*text, where, "Frame " + name) * angle_unit_scale(angle_unit, where);
    }
  });
  return {position, rotation_from_xyz_degrees(angles)};
}

Frame parse_point_attribute(const pugi::xml_node& attribute, const XmlFile& file) {
  const SourceRef where = file.where(attribute);
  const auto text = attribute_text(attribute);
  if (!text || text->empty()) {
    throw DescriptionError(where, "interface position has no value (expected x,y,z)");
  }
  return {parse_vec3(*text, length_unit_scale(unit_of(attribute), where), where),
          Quat::Identity()};
}

}  // namespace twin::aml
