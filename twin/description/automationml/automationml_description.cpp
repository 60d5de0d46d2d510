#include "twin/description/automationml/automationml_description.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cctype>
#include <map>
#include <set>
#include <unordered_map>

#include "twin/description/automationml/caex_values.hpp"
#include "twin/description/automationml/xml_file.hpp"

namespace twin {
namespace {

using aml::child;
using aml::for_each_child;
using aml::local_name;

using aml::normalize_id;

// "BaseLib@Lib/Class" (an alias into an external file) -> "Lib/Class".
std::string strip_alias(std::string_view path) {
  const auto at = path.find('@');
  return std::string(at == std::string_view::npos ? path : path.substr(at + 1));
}

std::string last_segment(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

bool has_mesh_extension(const std::filesystem::path& file) {
  static const std::set<std::string> extensions = {".obj", ".stl", ".dae", ".ply", ".gltf",
                                                   ".glb", ".fbx", ".3ds", ".off"};
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return extensions.count(ext) > 0;
}

std::string percent_decode(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '%' && i + 2 < text.size() && std::isxdigit(static_cast<unsigned char>(text[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(text[i + 2]))) {
      out += static_cast<char>(std::stoi(text.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += text[i];
    }
  }
  return out;
}

}  // namespace

// Reads one CAEX file into items. Owned by AutomationMLDescription's constructor.
class CaexReader {
 public:
  CaexReader(const aml::XmlFile& file, AutomationMLDescription& out) : file_(file), out_(out) {}

  void read() {
    const pugi::xml_node root = file_.document().document_element();
    if (local_name(root) != "CAEXFile") {
      throw DescriptionError(file_.where(root), "not a CAEX file: the root element is <" +
                                                    std::string(root.name()) +
                                                    ">, expected <CAEXFile>");
    }
    out_.schema_version_ = root.attribute("SchemaVersion").value();
    index_classes(root);

    bool any_hierarchy = false;
    for_each_child(root, "InstanceHierarchy", [&](const pugi::xml_node& hierarchy) {
      any_hierarchy = true;
      if (out_.product_name_.empty()) out_.product_name_ = product_name_of(hierarchy);
      collect_links(hierarchy);
      int top_level = 0;
      for_each_child(hierarchy, "InternalElement", [&](const pugi::xml_node&) { ++top_level; });
      // The one element at the top is the product; beside others, a group is a subassembly.
      const std::string none;
      for_each_child(hierarchy, "InternalElement",
                     [&](const pugi::xml_node& e) { read_element(e, top_level == 1 ? nullptr : &none); });
    });
    if (!any_hierarchy) {
      throw DescriptionError(file_.where(root), "the file has no InstanceHierarchy, so no parts");
    }
    emit_type_parameters();
    for (const pugi::xml_node& link : links_) read_link(link);
  }

 private:
  // --- classes -----------------------------------------------------------------------

  void index_classes(const pugi::xml_node& root) {
    for_each_child(root, "SystemUnitClassLib", [&](const pugi::xml_node& lib) {
      index_nested(lib, lib.attribute("Name").value(), "SystemUnitClass", unit_classes_);
    });
    for_each_child(root, "InterfaceClassLib", [&](const pugi::xml_node& lib) {
      index_nested(lib, lib.attribute("Name").value(), "InterfaceClass", interface_classes_);
    });
  }

  static void index_nested(const pugi::xml_node& parent, const std::string& path,
                           std::string_view element,
                           std::unordered_map<std::string, pugi::xml_node>& index) {
    for_each_child(parent, element, [&](const pugi::xml_node& c) {
      const std::string own = path + "/" + c.attribute("Name").value();
      index.emplace(own, c);
      index_nested(c, own, element, index);
    });
  }

  // The class and its bases, most derived first. Classes from other files (aliases that
  // this file does not define) end the chain.
  std::vector<pugi::xml_node> class_chain(
      const std::string& path, const std::unordered_map<std::string, pugi::xml_node>& index,
      const SourceRef& where) const {
    std::vector<pugi::xml_node> chain;
    std::string next = strip_alias(path);
    std::set<std::string> seen;
    while (!next.empty()) {
      const auto it = index.find(next);
      if (it == index.end()) break;
      if (!seen.insert(next).second) {
        throw DescriptionError(where, "class '" + next + "' derives from itself (RefBaseClassPath loop)");
      }
      chain.push_back(it->second);
      next = strip_alias(it->second.attribute("RefBaseClassPath").value());
    }
    return chain;
  }

  bool is_geometry_interface(const pugi::xml_node& interface, const std::filesystem::path& uri) const {
    const std::string ref = interface.attribute("RefBaseClassPath").value();
    std::vector<std::string> names = {last_segment(strip_alias(ref))};
    for (const auto& c : class_chain(ref, interface_classes_, file_.where(interface))) {
      names.push_back(c.attribute("Name").value());
      names.push_back(last_segment(strip_alias(c.attribute("RefBaseClassPath").value())));
    }
    auto named = [&](const char* n) { return std::find(names.begin(), names.end(), n) != names.end(); };
    if (named("COLLADAInterface")) return true;
    if (named("PLCopenXMLInterface")) return false;
    return (named("ExternalDataReference") || named("ExternalDataConnector")) && has_mesh_extension(uri);
  }

  // --- instances -----------------------------------------------------------------------

  std::string product_name_of(const pugi::xml_node& hierarchy) const {
    // The paper's layout: one element (the product) holding the parts.
    pugi::xml_node only;
    int count = 0;
    for_each_child(hierarchy, "InternalElement", [&](const pugi::xml_node& e) {
      only = e;
      ++count;
    });
    if (count == 1 && child(only, "InternalElement")) return only.attribute("Name").value();
    return hierarchy.attribute("Name").value();
  }

  void register_id(const pugi::xml_node& node, const std::string& id) {
    const auto [it, inserted] = ids_.emplace(id, node);
    if (!inserted) {
      throw DescriptionError(file_.where(node), "duplicate ID '" + id + "': " +
                                                    file_.where(it->second).to_string() +
                                                    " has it already");
    }
  }

  // `within`: null for the product's own element; else the subassembly the element lies in
  // (empty: none yet, so a group here is one).
  void read_element(const pugi::xml_node& element, const std::string* within) {
    const std::string raw_id = element.attribute("ID").value();
    if (raw_id.empty()) throw DescriptionError(file_.where(element), "InternalElement has no ID");
    const std::string id = normalize_id(raw_id);
    register_id(element, id);
    collect_links(element);

    if (child(element, "InternalElement")) {  // the product or a subassembly: its children are parts
      ++out_.group_count_;
      group_ids_.insert(id);
      read_precedences(element);
      const std::string* inner = within;
      std::string name;
      if (within == nullptr) {
        // The product's element: its groups are subassemblies; but a lone group in it is the
        // product's element again (an order holding a product holding the parts).
        int children = 0;
        for_each_child(element, "InternalElement", [&](const pugi::xml_node&) { ++children; });
        const bool lone_group = children == 1 && child(child(element, "InternalElement"), "InternalElement");
        inner = lone_group ? nullptr : &name;
      } else if (within->empty()) {
        name = element.attribute("Name").value();
        if (name.empty()) name = id;
        if (!subassembly_names_.insert(name).second) {
          throw DescriptionError(file_.where(element), "a second subassembly named '" + name + "'");
        }
        inner = &name;
      }  // a group inside a subassembly belongs to it: one level of subassemblies
      for_each_child(element, "InternalElement", [&](const pugi::xml_node& e) { read_element(e, inner); });
      return;
    }
    read_part(element, id, within ? *within : std::string());
  }

  void collect_links(const pugi::xml_node& element) {
    for_each_child(element, "InternalLink", [&](const pugi::xml_node& l) { links_.push_back(l); });
  }

  void read_part(const pugi::xml_node& element, const std::string& id, const std::string& subassembly) {
    read_precedences(element);  // where the parts stand at the top, with no product element
    CreatePartItem part;
    part.id = id;
    part.subassembly = subassembly;
    part.name = element.attribute("Name").value();
    part.where = file_.where(element);
    if (part.name.empty()) part.name = id;

    const std::string type_ref = element.attribute("RefBaseSystemUnitPath").value();
    std::vector<pugi::xml_node> chain;
    if (!type_ref.empty()) {
      part.type = strip_alias(type_ref);
      chain = class_chain(type_ref, unit_classes_, part.where);
      if (!chain.empty() && std::find(used_types_.begin(), used_types_.end(), part.type) == used_types_.end()) {
        used_types_.push_back(part.type);
        type_chains_[part.type] = chain;
      }
    }

    // Attributes: the class chain's, base first, then the instance's own on top.
    std::map<std::string, pugi::xml_node> attributes;
    for (auto c = chain.rbegin(); c != chain.rend(); ++c) {
      for_each_child(*c, "Attribute", [&](const pugi::xml_node& a) { attributes[a.attribute("Name").value()] = a; });
    }
    std::map<std::string, pugi::xml_node> own_attributes;
    for_each_child(element, "Attribute", [&](const pugi::xml_node& a) {
      attributes[a.attribute("Name").value()] = a;
      own_attributes[a.attribute("Name").value()] = a;
    });

    std::set<std::string> interface_names = declared_interfaces(chain);
    for_each_child(element, "ExternalInterface", [&](const pugi::xml_node& i) {
      const std::string name = i.attribute("Name").value();
      interface_names.insert(name);
      if (const std::string iid = i.attribute("ID").value(); !iid.empty()) {
        register_id(i, normalize_id(iid));
        interface_ids_[normalize_id(iid)] = {id, name};
      }
      std::optional<Frame> frame;
      if (const auto f = frame_attribute(i)) frame = aml::parse_frame(f, file_);
      part.interfaces[name] = frame;
      if (const auto joint = joint_of(i)) part.joints[name] = *joint;
    });
    // An instance Attribute named like an interface moves that interface for this part.
    for (const auto& [name, attribute] : own_attributes) {
      if (interface_names.count(name) && has_value(attribute)) {
        part.interfaces[name] = aml::parse_point_attribute(attribute, file_);
      }
    }

    for (const auto& [name, attribute] : attributes) {
      if (interface_names.count(name) || name == "Frame") continue;
      if (const auto text = aml::attribute_text(attribute)) part.attributes[name] = *text;
    }
    if (auto it = part.attributes.find("color"); it != part.attributes.end() && !it->second.empty()) {
      part.color = it->second;
    }
    if (auto it = attributes.find("orientation"); it != attributes.end() && has_value(it->second)) {
      part.orientation = aml::parse_orientation(it->second, file_);
    } else if (auto frame = own_attributes.find("Frame"); frame != own_attributes.end()) {
      part.orientation = aml::parse_frame(frame->second, file_).rotation;
    }
    part.mesh = find_mesh(element, chain);
    out_.items_.emplace_back(std::move(part));
  }

  static bool has_value(const pugi::xml_node& attribute) {
    const auto text = aml::attribute_text(attribute);
    return text && !text->empty();
  }

  // The joint an ExternalInterface declares (docs/automationml.md, "Joints"): an Attribute
  // "Joint" naming its kind, and for a screw "Pitch", a length per turn.
  std::optional<Joint> joint_of(const pugi::xml_node& interface) const {
    pugi::xml_node kind, pitch;
    for (pugi::xml_node a = interface.first_child(); a; a = a.next_sibling()) {
      if (local_name(a) != "Attribute") continue;
      const std::string_view name = a.attribute("Name").value();
      if (name == "Joint") kind = a;
      if (name == "Pitch") pitch = a;
    }
    if (!kind && !pitch) return std::nullopt;
    const std::string interface_name = interface.attribute("Name").value();
    if (!kind) throw DescriptionError(file_.where(pitch), "interface '" + interface_name + "' has a Pitch but no Joint");
    Joint joint;
    joint.where = file_.where(kind);
    const std::string text = aml::attribute_text(kind).value_or("");
    const auto parsed = joint_kind(text);
    if (!parsed) {
      throw DescriptionError(joint.where, "interface '" + interface_name + "' declares joint '" + text +
                                              "', which is none of " + joint_names());
    }
    joint.kind = *parsed;
    if (joint.kind == Joint::Kind::screw) {
      if (!pitch) throw DescriptionError(joint.where, "screw joint of interface '" + interface_name + "' has no Pitch");
      const SourceRef at = file_.where(pitch);
      const std::string value = aml::attribute_text(pitch).value_or("");
      char* end = nullptr;
      const double number = std::strtod(value.c_str(), &end);
      if (value.empty() || end != value.c_str() + value.size() || !std::isfinite(number) || number <= 0) {
        throw DescriptionError(at, "Pitch '" + value + "' of interface '" + interface_name + "' is not a length above 0");
      }
      joint.pitch = number * aml::length_unit_scale(pitch.attribute("Unit").value(), at);
    } else if (pitch) {
      throw DescriptionError(file_.where(pitch), "interface '" + interface_name + "' has a Pitch, but its joint is " +
                                                     joint_name(joint.kind) + ", not a screw");
    }
    return joint;
  }

  static pugi::xml_node frame_attribute(const pugi::xml_node& interface) {
    for (pugi::xml_node a = interface.first_child(); a; a = a.next_sibling()) {
      if (local_name(a) == "Attribute" && std::string_view(a.attribute("Name").value()) == "Frame") return a;
    }
    return {};
  }

  static std::set<std::string> declared_interfaces(const std::vector<pugi::xml_node>& chain) {
    std::set<std::string> names;
    for (const auto& c : chain) {
      for_each_child(c, "ExternalInterface", [&](const pugi::xml_node& i) { names.insert(i.attribute("Name").value()); });
    }
    return names;
  }

  // The first geometry reference on the instance, else on its class chain (derived first).
  std::optional<MeshRef> find_mesh(const pugi::xml_node& element, const std::vector<pugi::xml_node>& chain) const {
    std::vector<pugi::xml_node> holders = {element};
    holders.insert(holders.end(), chain.begin(), chain.end());
    for (const auto& holder : holders) {
      for (pugi::xml_node i = holder.first_child(); i; i = i.next_sibling()) {
        if (local_name(i) != "ExternalInterface") continue;
        pugi::xml_node uri_attribute, unit_attribute;
        for_each_child(i, "Attribute", [&](const pugi::xml_node& a) {
          const std::string_view name = a.attribute("Name").value();
          if (name == "refURI") uri_attribute = a;
          if (name == "LengthUnit") unit_attribute = a;
        });
        if (!uri_attribute) continue;
        const std::string uri = aml::attribute_text(uri_attribute).value_or("");
        if (!is_geometry_interface(i, uri)) continue;
        MeshRef mesh = resolve_mesh(uri, file_.where(uri_attribute));
        if (unit_attribute) {
          if (is_collada(mesh.file)) {
            // Its <asset><unit> is applied when it is read: a LengthUnit would scale it twice.
            throw DescriptionError(file_.where(unit_attribute),
                                   "LengthUnit does not apply to the COLLADA mesh '" + uri +
                                       "': a .dae file states its own unit (<asset><unit meter=...>), which is used");
          }
          mesh.scale = aml::length_unit_scale(aml::attribute_text(unit_attribute).value_or(""), file_.where(unit_attribute));
        }
        return mesh;
      }
    }
    return std::nullopt;
  }

  static bool is_collada(const std::filesystem::path& file) {
    std::string extension = file.extension().string();
    for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return extension == ".dae" || extension == ".zae";  // COLLADA, and zipped COLLADA
  }

  MeshRef resolve_mesh(std::string uri, const SourceRef& where) const {
    if (uri.empty()) throw DescriptionError(where, "geometry reference has an empty refURI");
    if (const auto hash = uri.find('#'); hash != std::string::npos) uri.resize(hash);  // COLLADA node id
    const bool has_scheme = uri.find("://") != std::string::npos || uri.rfind("file:", 0) == 0;
    const std::filesystem::path relative(percent_decode(uri));
    if (has_scheme || relative.is_absolute()) {
      throw DescriptionError(where, "mesh reference '" + uri +
                                        "' must be a path relative to the product's folder");
    }
    const auto folder = std::filesystem::weakly_canonical(std::filesystem::absolute(file_.path()).parent_path());
    const auto file = std::filesystem::weakly_canonical(folder / relative);
    const auto [f, _] = std::mismatch(folder.begin(), folder.end(), file.begin(), file.end());
    if (f != folder.end()) {
      throw DescriptionError(where, "mesh reference '" + uri + "' leaves the product's folder " + folder.string());
    }
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) {
      throw DescriptionError(where, "mesh file '" + uri + "' does not exist (looked for " + file.string() + ")");
    }
    return {file, where};
  }

  // --- type parameters (the paper's "parameter" items) ----------------------------------

  void emit_type_parameters() {
    for (const std::string& type : used_types_) {
      const auto& chain = type_chains_.at(type);
      const std::set<std::string> names = declared_interfaces(chain);
      std::map<std::string, ParameterItem> parameters;
      for (auto c = chain.rbegin(); c != chain.rend(); ++c) {  // base first; derived overrides
        for_each_child(*c, "ExternalInterface", [&](const pugi::xml_node& i) {
          ParameterItem& p = parameters[i.attribute("Name").value()];
          p.type = type;
          p.interface = i.attribute("Name").value();
          p.where = file_.where(i);
          if (const auto f = frame_attribute(i)) p.frame = aml::parse_frame(f, file_);
          if (const auto joint = joint_of(i)) p.joint = joint;
        });
        for_each_child(*c, "Attribute", [&](const pugi::xml_node& a) {
          const std::string name = a.attribute("Name").value();
          if (names.count(name) && has_value(a)) {
            ParameterItem& p = parameters[name];
            p.frame = aml::parse_point_attribute(a, file_);
          }
        });
      }
      for (auto& [_, p] : parameters) out_.items_.emplace_back(std::move(p));
    }
  }

  // --- precedences (docs/automationml.md): ordering constraints, never geometry ---------
  //   <Attribute Name="AssemblyPrecedence">
  //     <Attribute Name="..."><Attribute Name="Before"><Value>ID</Value></Attribute>
  //                           <Attribute Name="After"><Value>ID</Value></Attribute></Attribute>

  void read_precedences(const pugi::xml_node& element) {
    for_each_child(element, "Attribute", [&](const pugi::xml_node& list) {
      if (std::string_view(list.attribute("Name").value()) != "AssemblyPrecedence") return;
      for_each_child(list, "Attribute", [&](const pugi::xml_node& rule) {
        PrecedenceItem p;
        p.where = file_.where(rule);
        for (const auto& [name, id] : {std::pair{"Before", &p.before}, std::pair{"After", &p.after}}) {
          pugi::xml_node side;
          const std::string_view wanted = name;  // a lambda may not capture a structured binding (C++17)
          for_each_child(rule, "Attribute", [&](const pugi::xml_node& a) {
            if (std::string_view(a.attribute("Name").value()) == wanted) side = a;
          });
          const auto text = side ? aml::attribute_text(side) : std::nullopt;
          if (!text || text->empty()) {
            throw DescriptionError(p.where, std::string("precedence '") + rule.attribute("Name").value() + "' has no " +
                                                name + " (an Attribute with the part's ID as its Value)");
          }
          *id = normalize_id(*text);
        }
        out_.items_.emplace_back(std::move(p));
      });
    });
  }

  // --- links -----------------------------------------------------------------------------

  void read_link(const pugi::xml_node& link) {
    const SourceRef where = file_.where(link);
    ConnectionItem c;
    c.name = link.attribute("Name").value();
    c.where = where;
    std::tie(c.part_a, c.interface_a) = link_side(link.attribute("RefPartnerSideA").value(), "RefPartnerSideA", where);
    std::tie(c.part_b, c.interface_b) = link_side(link.attribute("RefPartnerSideB").value(), "RefPartnerSideB", where);
    out_.items_.emplace_back(std::move(c));
  }

  // "<element ID>:<interface name>" (the paper's files) or a bare interface ID (CAEX 3.0
  // editors). Returns the part ID and the interface name.
  std::pair<std::string, std::string> link_side(const std::string& side, const std::string& attribute,
                                                const SourceRef& where) const {
    if (side.empty()) throw DescriptionError(where, attribute + " is missing");
    const auto colon = side.find(':');
    if (colon == std::string::npos) {
      const auto it = interface_ids_.find(normalize_id(side));
      if (it == interface_ids_.end()) {
        throw DescriptionError(where, attribute + " '" + side + "' is neither <element ID>:<interface> nor the ID of a part's ExternalInterface");
      }
      return it->second;
    }
    const std::string id = normalize_id(side.substr(0, colon));
    if (group_ids_.count(id)) {
      throw DescriptionError(where, attribute + " '" + side + "' names an element that holds other elements (an assembly), not a part");
    }
    return {id, side.substr(colon + 1)};
  }

  const aml::XmlFile& file_;
  AutomationMLDescription& out_;
  std::unordered_map<std::string, pugi::xml_node> unit_classes_;
  std::unordered_map<std::string, pugi::xml_node> interface_classes_;
  std::vector<std::string> used_types_;
  std::map<std::string, std::vector<pugi::xml_node>> type_chains_;
  std::unordered_map<std::string, pugi::xml_node> ids_;
  std::set<std::string> group_ids_;
  std::set<std::string> subassembly_names_;
  std::unordered_map<std::string, std::pair<std::string, std::string>> interface_ids_;
  std::vector<pugi::xml_node> links_;
};

AutomationMLDescription::AutomationMLDescription(const std::filesystem::path& file) : source_(file) {
  const aml::XmlFile xml(file);
  CaexReader(xml, *this).read();
}

}  // namespace twin
