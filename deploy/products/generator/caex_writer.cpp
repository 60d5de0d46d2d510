#include "deploy/products/generator/caex_writer.hpp"

#include <cstdint>
#include <cstdio>
#include <stdexcept>

namespace products {
namespace {

std::uint64_t fnv1a(const std::string& text, std::uint64_t hash) {
  for (unsigned char c : text) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  return hash;
}

std::string format_mm(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", v == 0 ? 0.0 : v);
  return buffer;
}

pugi::xml_node add_attribute(pugi::xml_node parent, const std::string& name, const std::string& value,
                             const char* value_element) {
  pugi::xml_node a = parent.append_child("Attribute");
  a.append_attribute("Name") = name.c_str();
  a.append_attribute("AttributeDataType") = "xs:string";
  a.append_child(value_element).text() = value.c_str();
  return a;
}

}  // namespace

std::string stable_uuid(const std::string& seed) {
  const std::uint64_t a = fnv1a(seed, 14695981039346656037ull);
  const std::uint64_t b = fnv1a(seed + "#", a);
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%08x-%04x-4%03x-8%03x-%012llx", static_cast<unsigned>(a >> 32),
                static_cast<unsigned>((a >> 16) & 0xffff), static_cast<unsigned>(a & 0xfff),
                static_cast<unsigned>((b >> 48) & 0xfff), static_cast<unsigned long long>(b & 0xffffffffffffull));
  return buffer;
}

CaexWriter::CaexWriter(const std::string& file_name, const std::string& product_name)
    : interface_lib_name_(product_name + "Interfaces"), unit_lib_name_(product_name + "Parts") {
  auto declaration = document_.append_child(pugi::node_declaration);
  declaration.append_attribute("version") = "1.0";
  declaration.append_attribute("encoding") = "utf-8";
  pugi::xml_node root = document_.append_child("CAEXFile");
  root.append_attribute("SchemaVersion") = "3.0";
  root.append_attribute("FileName") = file_name.c_str();
  root.append_attribute("xmlns") = "http://www.dke.de/CAEX";
  root.append_attribute("xmlns:xsi") = "http://www.w3.org/2001/XMLSchema-instance";
  root.append_attribute("xsi:schemaLocation") = "http://www.dke.de/CAEX CAEX_ClassModel_V.3.0.xsd";
  root.append_child("SuperiorStandardVersion").text() = "AutomationML 2.10";
  pugi::xml_node info = root.append_child("SourceDocumentInformation");
  info.append_attribute("OriginName") = "agile-cell make_products";
  info.append_attribute("OriginID") = stable_uuid("make_products").c_str();
  info.append_attribute("OriginVersion") = "1.0";
  info.append_attribute("LastWritingDateTime") = "2026-11-23T00:00:00";

  pugi::xml_node hierarchy = root.append_child("InstanceHierarchy");
  hierarchy.append_attribute("Name") = (product_name + "Order").c_str();
  product_ = hierarchy.append_child("InternalElement");
  product_.append_attribute("Name") = product_name.c_str();
  product_.append_attribute("ID") = stable_uuid(product_name).c_str();

  // The AutomationML classes used for geometry references, as AML editors embed them.
  pugi::xml_node aml_lib = root.append_child("InterfaceClassLib");
  aml_lib.append_attribute("Name") = "AutomationMLInterfaceClassLib";
  pugi::xml_node base = aml_lib.append_child("InterfaceClass");
  base.append_attribute("Name") = "AutomationMLBaseInterface";
  pugi::xml_node connector = base.append_child("InterfaceClass");
  connector.append_attribute("Name") = "ExternalDataConnector";
  connector.append_attribute("RefBaseClassPath") = "AutomationMLInterfaceClassLib/AutomationMLBaseInterface";
  pugi::xml_node reference = connector.append_child("InterfaceClass");
  reference.append_attribute("Name") = "ExternalDataReference";
  reference.append_attribute("RefBaseClassPath") =
      "AutomationMLInterfaceClassLib/AutomationMLBaseInterface/ExternalDataConnector";

  interface_lib_ = root.append_child("InterfaceClassLib");
  interface_lib_.append_attribute("Name") = interface_lib_name_.c_str();
  interface_lib_.append_child("Version").text() = "1.0.0";
  unit_lib_ = root.append_child("SystemUnitClassLib");
  unit_lib_.append_attribute("Name") = unit_lib_name_.c_str();
  unit_lib_.append_child("Version").text() = "1.0.0";
}

void CaexWriter::interface_class(const std::string& name) {
  interface_lib_.append_child("InterfaceClass").append_attribute("Name") = name.c_str();
}

pugi::xml_node CaexWriter::unit_class(const std::string& name, const std::string& base) {
  pugi::xml_node c = unit_lib_.append_child("SystemUnitClass");
  c.append_attribute("Name") = name.c_str();
  if (!base.empty()) c.append_attribute("RefBaseClassPath") = (unit_lib_name_ + "/" + base).c_str();
  return c;
}

void CaexWriter::interface_point(pugi::xml_node unit_class, const std::string& name,
                                 const std::string& interface_class, const Eigen::Vector3d& mm, const std::string& joint) {
  pugi::xml_node a = add_attribute(unit_class, name,
                                   format_mm(mm.x()) + "," + format_mm(mm.y()) + "," + format_mm(mm.z()),
                                   "DefaultValue");
  a.insert_attribute_after("Unit", a.attribute("Name")) = "mm";
  pugi::xml_node i = unit_class.append_child("ExternalInterface");
  i.append_attribute("Name") = name.c_str();
  i.append_attribute("RefBaseClassPath") = (interface_lib_name_ + "/" + interface_class).c_str();
  i.append_attribute("ID") = stable_uuid(std::string(unit_class.attribute("Name").value()) + "/" + name).c_str();
  if (!joint.empty()) {
    pugi::xml_node j = i.append_child("Attribute");
    j.append_attribute("Name") = "Joint";
    j.append_attribute("AttributeDataType") = "xs:string";
    j.append_child("Value").text() = joint.c_str();
  }
}

void CaexWriter::geometry(pugi::xml_node unit_class, const std::string& ref_uri) {
  pugi::xml_node i = unit_class.append_child("ExternalInterface");
  i.append_attribute("Name") = "geometry";
  i.append_attribute("RefBaseClassPath") =
      "AutomationMLInterfaceClassLib/AutomationMLBaseInterface/ExternalDataConnector/ExternalDataReference";
  i.append_attribute("ID") = stable_uuid(std::string(unit_class.attribute("Name").value()) + "/geometry").c_str();
  pugi::xml_node uri = add_attribute(i, "refURI", ref_uri, "Value");
  uri.attribute("AttributeDataType") = "xs:anyURI";
}

pugi::xml_node CaexWriter::part(const std::string& name, const std::string& unit_class, const std::string& color,
                                const std::string& orientation) {
  pugi::xml_node e = product_.append_child("InternalElement");
  e.append_attribute("Name") = name.c_str();
  e.append_attribute("ID") = stable_uuid(product_.attribute("Name").value() + std::string("/") + name).c_str();
  e.append_attribute("RefBaseSystemUnitPath") = (unit_lib_name_ + "/" + unit_class).c_str();
  add_attribute(e, "color", color, "Value");
  pugi::xml_node o = add_attribute(e, "orientation", orientation, "Value");
  o.insert_attribute_after("Unit", o.attribute("Name")) = "deg";
  return e;
}

void CaexWriter::link(const std::string& name, pugi::xml_node part_a, const std::string& interface_a,
                      pugi::xml_node part_b, const std::string& interface_b) {
  pugi::xml_node l = product_.append_child("InternalLink");
  l.append_attribute("Name") = name.c_str();
  l.append_attribute("RefPartnerSideA") = (std::string(part_a.attribute("ID").value()) + ":" + interface_a).c_str();
  l.append_attribute("RefPartnerSideB") = (std::string(part_b.attribute("ID").value()) + ":" + interface_b).c_str();
}

void CaexWriter::save(const std::string& path) const {
  if (!document_.save_file(path.c_str(), "\t", pugi::format_default, pugi::encoding_utf8)) {
    throw std::runtime_error("cannot write " + path);
  }
}

}  // namespace products
