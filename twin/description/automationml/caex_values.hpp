#pragma once
// Reading values out of CAEX Attribute elements: text, lengths with units, x,y,z triples,
// orientations and the AutomationML Frame attribute.

#include <optional>
#include <string>

#include <pugixml.hpp>

#include "twin/description/automationml/xml_file.hpp"
#include "twin/model/frame.hpp"

namespace twin::aml {

// "{2DDC2CF5-...}" and "2ddc2cf5-..." are the same ID.
std::string normalize_id(std::string_view id);

// An Attribute's <Value>, else its <DefaultValue>, trimmed; empty when it has neither.
std::optional<std::string> attribute_text(const pugi::xml_node& attribute);

// Metres per unit for a length Unit ("m" when absent; "mm", "cm", "dm", "km" and
// spelled-out names); throws naming `where` for anything else.
double length_unit_scale(const std::string& unit, const SourceRef& where);

// "x,y,z" (commas, spaces allowed around them) as three finite numbers, times `scale`.
Vec3 parse_vec3(const std::string& text, double scale, const SourceRef& where);

// "rx,ry,rz" in degrees (or radians when the attribute's Unit says rad).
Quat parse_orientation(const pugi::xml_node& attribute, const XmlFile& file);

// An AutomationML Frame attribute (children x, y, z, rx, ry, rz; absent ones are 0).
Frame parse_frame(const pugi::xml_node& frame_attribute, const XmlFile& file);

// An Attribute that holds an interface position: "x,y,z" with an optional Unit.
Frame parse_point_attribute(const pugi::xml_node& attribute, const XmlFile& file);

}  // namespace twin::aml
