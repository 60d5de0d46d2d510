#include "deploy/cellctl/product_report.hpp"

#include <cmath>
#include <map>

#include "deploy/cellctl/text_table.hpp"
#include "twin/planning/subassembly_planner.hpp"

namespace cellctl {

twin::Vec3 xyz_degrees(const twin::Quat& q) {
  const twin::Vec3 zyx = q.toRotationMatrix().eulerAngles(2, 1, 0);
  return twin::Vec3(zyx[2], zyx[1], zyx[0]) * (180.0 / M_PI);
}

namespace {

// Mesh file -> (what loading repaired, found or simplified, the parts that use it), for the files with any.
std::map<std::string, std::pair<std::string, std::vector<std::string>>> mesh_repairs(const twin::LoadedProduct& loaded) {
  std::map<std::string, std::pair<std::string, std::vector<std::string>>> out;
  for (std::size_t i = 0; i < loaded.meshes.size(); ++i) {
    const auto& part = loaded.product.parts()[i];
    const std::string report = loaded.meshes[i] ? sim::loading_report(*loaded.meshes[i]) : "";
    if (report.empty()) continue;
    auto& entry = out[part.mesh->file.filename().string()];
    entry.first = report;
    entry.second.push_back(part.name);
  }
  return out;
}

}  // namespace

nlohmann::json product_json(const twin::LoadedProduct& loaded, const twin::InterferenceCheck& check) {
  const twin::Product& product = loaded.product;
  nlohmann::json parts = nlohmann::json::array();
  for (const auto& part : product.parts()) {
    const twin::Vec3 p = part.final_pose.translation();
    const twin::Quat q(part.final_pose.linear());
    nlohmann::json j = {{"id", part.id},
                        {"name", part.name},
                        {"type", twin::short_type_name(part.type)},
                        {"position", {p.x(), p.y(), p.z()}},
                        {"orientation", {q.w(), q.x(), q.y(), q.z()}}};
    if (part.color) j["color"] = *part.color;
    if (part.mesh) j["mesh"] = part.mesh->file.filename().string();
    if (!part.subassembly.empty()) j["subassembly"] = part.subassembly;
    parts.push_back(std::move(j));
  }
  nlohmann::json connections = nlohmann::json::array();
  for (const auto& c : product.connections()) {
    connections.push_back({{"part1", product.parts()[c.part1].name},
                           {"interface1", c.interface1},
                           {"part2", product.parts()[c.part2].name},
                           {"interface2", c.interface2},
                           {"name", c.name}});
  }
  nlohmann::json interferences = nlohmann::json::array();
  for (const auto& i : check.overlaps) {
    interferences.push_back({{"part1", product.parts()[i.part1].name},
                             {"part2", product.parts()[i.part2].name},
                             {"depth", i.depth},
                             {"message", twin::describe(product, i)}});
  }
  nlohmann::json repairs = nlohmann::json::array();
  for (const auto& [file, found] : mesh_repairs(loaded)) {
    repairs.push_back({{"mesh", file}, {"parts", found.second}, {"message", found.first}});
  }
  nlohmann::json not_closed = nlohmann::json::array();
  for (const auto p : check.not_closed) not_closed.push_back(product.parts()[p].name);
  return {{"schema", "agile-cell/product"},
          {"version", 1},
          {"product", product.name()},
          {"source", product.source().string()},
          {"units", {{"length", "m"}}},
          {"parts", parts},
          {"connections", connections},
          {"interferences", interferences},
          {"meshes_not_closed", not_closed},
          {"mesh_repairs", repairs}};
}

void print_product_table(const twin::LoadedProduct& loaded, const twin::InterferenceCheck& check, std::ostream& out) {
  const twin::Product& product = loaded.product;
  out << "Product '" << product.name() << "' from " << product.source().string() << ": "
      << product.parts().size() << " parts, " << product.connections().size() << " links\n\n";
  TextTable parts({"#", "part", "type", "color", "x mm", "y mm", "z mm", "rx deg", "ry deg", "rz deg", "mesh"});
  for (std::size_t i = 0; i < product.parts().size(); ++i) {
    const auto& part = product.parts()[i];
    const twin::Vec3 p = part.final_pose.translation() * 1000.0;
    const twin::Vec3 r = xyz_degrees(twin::Quat(part.final_pose.linear()));
    parts.add_row({std::to_string(i + 1), part.name, twin::short_type_name(part.type), part.color.value_or("-"),
                   fixed(p.x(), 2), fixed(p.y(), 2), fixed(p.z(), 2), fixed(r.x(), 1), fixed(r.y(), 1),
                   fixed(r.z(), 1), part.mesh ? part.mesh->file.filename().string() : "-"});
  }
  parts.print(out);
  for (const auto& s : twin::subassemblies_of(product)) {
    out << "subassembly " << s.name << ":";
    for (twin::PartIndex p : s.members) out << ' ' << product.parts()[p].name;
    out << " (built first, then inserted as one)\n";
  }
  out << '\n';
  TextTable links({"link", "part", "interface", "part", "interface"});
  for (const auto& c : product.connections()) {
    links.add_row({c.name, product.parts()[c.part1].name, c.interface1, product.parts()[c.part2].name, c.interface2});
  }
  links.print(out);
  out << '\n';
  if (check.overlaps.empty()) {
    out << "No parts overlap in the finished product.\n";
  } else {
    out << check.overlaps.size() << " overlap" << (check.overlaps.size() == 1 ? "" : "s")
        << " in the finished product (no plan can build these):\n";
    TextTable overlaps({"part", "overlaps", "depth mm", "finding"});
    for (const auto& i : check.overlaps) {
      overlaps.add_row({product.parts()[i.part2].name, product.parts()[i.part1].name, fixed(i.depth * 1000, 2),
                        twin::describe(product, i)});
    }
    overlaps.print(out);
  }
  for (const auto& [file, found] : mesh_repairs(loaded)) {
    std::string parts;
    for (const auto& name : found.second) parts += (parts.empty() ? "" : ", ") + name;
    out << "note: mesh " << file << " (" << parts << "): " << found.first << '\n';
  }
  for (const auto p : check.not_closed) {
    out << "note: the mesh of " << product.parts()[p].name
        << " is not closed: it has no inside, and overlaps into it are not checked\n";
  }
}

}  // namespace cellctl
