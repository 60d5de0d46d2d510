// A generated wall of 1000 blocks: every block linked to its left and lower neighbour,
// so placement must walk 1000 parts and check some 1000 loops.

#include <fstream>
#include <sstream>

#include <unistd.h>

#include "tests/twin/test_support.hpp"

namespace {

std::string wall_aml(int columns, int rows) {
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
  aml << "</SystemUnitClass></SystemUnitClassLib>\n</CAEXFile>\n";
  return aml.str();
}

}  // namespace

TEST_CASE("a generated product of 1000 parts is placed correctly", "[placement][scale]") {
  constexpr int columns = 25, rows = 40;
  const auto file = std::filesystem::temp_directory_path() / ("wall-" + std::to_string(::getpid()) + ".aml");
  std::ofstream(file) << wall_aml(columns, rows);
  const auto loaded = test::load(file);
  std::filesystem::remove(file);

  const auto& product = loaded.product;
  REQUIRE(product.parts().size() == 1000);
  CHECK(product.connections().size() == static_cast<std::size_t>((columns - 1) * rows + columns * (rows - 1)));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns; ++c) {
      const auto name = "b-" + std::to_string(c) + "-" + std::to_string(r);
      const twin::Vec3 p = test::position_mm(product, name);
      if ((p - twin::Vec3(20.0 * c, 10.0 * r, 0)).norm() > 1e-6) {
        FAIL(name << " at " << p.transpose() << " mm");
      }
    }
  }
}
