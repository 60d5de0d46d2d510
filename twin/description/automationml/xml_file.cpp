#include "twin/description/automationml/xml_file.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>

namespace twin::aml {

XmlFile::XmlFile(const std::filesystem::path& path) : path_(path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw DescriptionError({path.string(), 0, ""}, "cannot open the file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  text_ = buffer.str();

  line_starts_.push_back(0);
  for (std::size_t i = 0; i < text_.size(); ++i) {
    if (text_[i] == '\n') line_starts_.push_back(i + 1);
  }

  // parse_doctype keeps a DOCTYPE as a node so that it can be refused; pugixml never
  // expands user-defined entities, so nothing grows or loops before that check.
  const pugi::xml_parse_result result = document_.load_buffer(
      text_.data(), text_.size(), pugi::parse_default | pugi::parse_doctype, pugi::encoding_utf8);
  if (!result) {
    std::string message = std::string("not well-formed XML: ") + result.description();
    if (result.offset + 1 >= static_cast<std::ptrdiff_t>(text_.size()) && result.status != pugi::status_no_document_element) {
      message += " (the file ends in the middle of an element: truncated?)";
    }
    throw DescriptionError({path.string(), line_at(result.offset), ""}, message);
  }
  for (pugi::xml_node n = document_.first_child(); n; n = n.next_sibling()) {
    if (n.type() == pugi::node_doctype) {
      throw DescriptionError({path.string(), line_of(n), "<!DOCTYPE>"},
                             "document type declarations (DTD, entities) are not accepted in "
                             "CAEX files");
    }
  }
}

int XmlFile::line_at(std::ptrdiff_t offset) const {
  if (offset < 0) return 0;
  const auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(),
                                   static_cast<std::size_t>(offset));
  return static_cast<int>(it - line_starts_.begin());
}

int XmlFile::line_of(const pugi::xml_node& node) const { return line_at(node.offset_debug()); }

SourceRef XmlFile::where(const pugi::xml_node& node) const {
  std::string element(local_name(node));
  if (const auto name = node.attribute("Name")) element += std::string(" \"") + name.value() + "\"";
  return {path_.string(), line_of(node), element};
}

std::string_view local_name(const pugi::xml_node& node) {
  std::string_view name = node.name();
  const auto colon = name.find(':');
  return colon == std::string_view::npos ? name : name.substr(colon + 1);
}

pugi::xml_node child(const pugi::xml_node& node, std::string_view name) {
  for (pugi::xml_node c = node.first_child(); c; c = c.next_sibling()) {
    if (c.type() == pugi::node_element && local_name(c) == name) return c;
  }
  return {};
}

}  // namespace twin::aml
