#pragma once
// A generated wall of columns x rows blocks 20 x 10 mm (x, y), each linked to its left and
// lower neighbour: a product of any size for scale tests and benchmarks.

#include <sstream>
#include <string>

namespace test {

inline std::string wall_aml(int columns, int rows, const std::string& mesh = "") {
  std::ostringstream aml;
  aml << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
         "<CAEXFile SchemaVersion=\"3.0\" FileName=\"wall.aml\" xmlns=\"http://www.dke.de/CAEX\">\n"
         "<InstanceHierarchy Name=\"Order\"><InternalElement Name=\"Wall\" ID=\"wall\">\n";
  auto id = [](int c, int r) { return "b-" + std::to_string(c) + "-" + std::to_string(r); };
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns; ++c) {
      aml << "<InternalElement Name=\"" << id(c, r) << "\" ID=\"" << id(c, r)
          << "\" RefBaseSystemUnitPath=\"Lib/Block\"/>\n";
      if (c > 0) {
        aml << "<InternalLink Name=\"h" << id(c, r) << "\" RefPartnerSideA=\"" << id(c - 1, r)
            << ":right\" RefPartnerSideB=\"" << id(c, r) << ":left\"/>\n";
      }
      if (r > 0) {
        aml << "<InternalLink Name=\"v" << id(c, r) << "\" RefPartnerSideA=\"" << id(c, r - 1)
            << ":top\" RefPartnerSideB=\"" << id(c, r) << ":bottom\"/>\n";
      }
    }
  }
  aml << "</InternalElement></InstanceHierarchy>\n<SystemUnitClassLib Name=\"Lib\"><SystemUnitClass Name=\"Block\">\n";
  const std::pair<const char*, const char*> interfaces[] = {
      {"bottom", "0,0,0"}, {"top", "0,10,0"}, {"left", "-10,5,0"}, {"right", "10,5,0"}};
  for (const auto& [name, xyz] : interfaces) {
    aml << "<Attribute Name=\"" << name << "\" Unit=\"mm\"><DefaultValue>" << xyz << "</DefaultValue></Attribute>"
        << "<ExternalInterface Name=\"" << name << "\" ID=\"i-" << name << "\"/>\n";
  }
  if (!mesh.empty()) {
    aml << "<ExternalInterface Name=\"geometry\" ID=\"i-geometry\" RefBaseClassPath=\"ExternalDataReference\">"
        << "<Attribute Name=\"refURI\"><Value>" << mesh << "</Value></Attribute></ExternalInterface>\n";
  }
  aml << "</SystemUnitClass></SystemUnitClassLib>\n</CAEXFile>\n";
  return aml.str();
}


// The block's mesh for wall_aml: 19.8 x 10 x 19.8 mm (0.1 mm play on each side).
inline std::string wall_block_obj() {
  return "o block\nv -0.0099 0 -0.0099\nv 0.0099 0 -0.0099\nv 0.0099 0 0.0099\nv -0.0099 0 0.0099\n"
         "v -0.0099 0.01 -0.0099\nv 0.0099 0.01 -0.0099\nv 0.0099 0.01 0.0099\nv -0.0099 0.01 0.0099\n"
         "f 1 2 3 4\nf 8 7 6 5\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n";
}

}  // namespace test
