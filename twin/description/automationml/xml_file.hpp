#pragma once
// An XML file loaded for reading with line numbers for messages. Rejects DTDs: CAEX
// never needs one, and entity declarations are how "billion laughs" files attack parsers.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <pugixml.hpp>

#include "twin/model/source_ref.hpp"

namespace twin::aml {

class XmlFile {
 public:
  explicit XmlFile(const std::filesystem::path& path);  // throws DescriptionError

  const pugi::xml_document& document() const { return document_; }
  const std::filesystem::path& path() const { return path_; }
  int line_of(const pugi::xml_node& node) const;
  // "InternalElement "peg1"" at the node's line.
  SourceRef where(const pugi::xml_node& node) const;

 private:
  int line_at(std::ptrdiff_t offset) const;

  std::filesystem::path path_;
  std::string text_;
  std::vector<std::size_t> line_starts_;
  pugi::xml_document document_;
};

// Element name without a namespace prefix: "caex:InternalElement" -> "InternalElement".
std::string_view local_name(const pugi::xml_node& node);
// First child element with that local name, or an empty node.
pugi::xml_node child(const pugi::xml_node& node, std::string_view name);

// Calls f(child) for each child element with that local name, in document order.
template <class F>
void for_each_child(const pugi::xml_node& node, std::string_view name, F&& f) {
  for (pugi::xml_node c = node.first_child(); c; c = c.next_sibling()) {
    if (c.type() == pugi::node_element && local_name(c) == name) f(c);
  }
}

}  // namespace twin::aml
