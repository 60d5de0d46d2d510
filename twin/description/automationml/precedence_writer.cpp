#include "twin/description/automationml/precedence_writer.hpp"

#include <set>
#include <stdexcept>
#include <string_view>

#include <pugixml.hpp>

#include "twin/description/automationml/caex_values.hpp"

namespace twin {
namespace {

// Elements that come before Attributes in a CAEX InternalElement.
bool comes_before_attributes(std::string_view name) {
  for (std::string_view n : {"Description", "Version", "Revision", "Copyright", "AdditionalInformation", "Attribute"}) {
    if (name == n) return true;
  }
  return false;
}

pugi::xml_node find_element(const pugi::xml_node& root, const std::string& id) {
  return root.find_node([&](const pugi::xml_node& n) {
    return std::string_view(n.name()) == "InternalElement" && aml::normalize_id(n.attribute("ID").value()) == id;
  });
}

pugi::xml_node add_attribute(pugi::xml_node parent, const std::string& name) {
  pugi::xml_node before;
  for (pugi::xml_node c = parent.first_child(); c; c = c.next_sibling()) {
    if (c.type() == pugi::node_element && !comes_before_attributes(c.name())) {
      before = c;
      break;
    }
  }
  pugi::xml_node a = before ? parent.insert_child_before("Attribute", before) : parent.append_child("Attribute");
  a.append_attribute("Name") = name.c_str();
  return a;
}

pugi::xml_node precedence_list(pugi::xml_node element) {
  for (pugi::xml_node a : element.children("Attribute")) {
    if (std::string_view(a.attribute("Name").value()) == "AssemblyPrecedence") return a;
  }
  pugi::xml_node list = add_attribute(element, "AssemblyPrecedence");
  list.append_child("Description").text() =
      "Assembly order constraints (agile-cell): each child puts the part Before in before the part After. "
      "Not geometry.";
  return list;
}

void copy_meshes(const Product& product, const std::filesystem::path& from, const std::filesystem::path& to) {
  std::set<std::filesystem::path> files;
  for (const auto& p : product.parts()) {
    if (p.mesh) files.insert(p.mesh->file);
  }
  for (const auto& file : files) {
    const std::filesystem::path relative = std::filesystem::weakly_canonical(file).lexically_relative(from);
    if (relative.empty() || *relative.begin() == "..") {
      throw std::runtime_error(file.string() + " lies outside " + from.string() + ": not copied");
    }
    const std::filesystem::path target = to / relative;
    std::filesystem::create_directories(target.parent_path());
    std::filesystem::copy_file(file, target, std::filesystem::copy_options::overwrite_existing);
  }
}

}  // namespace

void write_with_precedences(const Product& product, const std::vector<std::pair<PartIndex, PartIndex>>& precedences,
                            const std::filesystem::path& out) {
  pugi::xml_document doc;
  const auto loaded = doc.load_file(product.source().c_str(), pugi::parse_full | pugi::parse_ws_pcdata);
  if (!loaded) throw std::runtime_error("cannot read " + product.source().string() + ": " + loaded.description());
  const auto& parts = product.parts();
  int n = 0;  // rules already there: the new ones are numbered on
  for (const pugi::xpath_node& rule : doc.select_nodes("//Attribute[@Name='AssemblyPrecedence']/Attribute")) {
    (void)rule;
    ++n;
  }
  for (const auto& [before, after] : precedences) {
    const pugi::xml_node part = find_element(doc, parts[after].id);
    if (!part) throw std::runtime_error("part '" + parts[after].name + "' not found in " + product.source().string());
    const pugi::xml_node parent = part.parent();
    const bool in_group = std::string_view(parent.name()) == "InternalElement";
    pugi::xml_node rule = add_attribute(precedence_list(in_group ? parent : part), "P" + std::to_string(++n));
    rule.append_child("Description").text() = (parts[before].name + " before " + parts[after].name).c_str();
    for (auto [side, index] : {std::pair{"Before", before}, std::pair{"After", after}}) {
      pugi::xml_node a = rule.append_child("Attribute");
      a.append_attribute("Name") = side;
      a.append_attribute("AttributeDataType") = "xs:string";
      a.append_child("Value").text() = parts[index].id.c_str();
    }
  }
  const std::filesystem::path out_dir = std::filesystem::weakly_canonical(std::filesystem::absolute(out).parent_path());
  const std::filesystem::path source_dir = std::filesystem::weakly_canonical(product.source()).parent_path();
  if (!doc.save_file(out.c_str(), "", pugi::format_raw, pugi::encoding_utf8)) {
    throw std::runtime_error("cannot write " + out.string());
  }
  if (out_dir != source_dir) copy_meshes(product, source_dir, out_dir);
}

}  // namespace twin
