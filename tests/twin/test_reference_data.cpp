// Real AutomationML files written by others (plant models, not products): the reader must
// read them without crashing and either build a product or say clearly why it cannot.
// Exits 77 (ctest: skipped) where ../shared/ is not beside the clone.

#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <filesystem>
#include <iostream>
#include <variant>

#include "sim/mesh/triangle_mesh.hpp"
#include "twin/description/automationml/automationml_description.hpp"
#include "twin/geometry/product_loader.hpp"

namespace {

const std::filesystem::path kDir = REFERENCE_DATA_DIR;

struct Found {
  std::size_t parts = 0, links = 0;
};

Found count_items(const twin::AutomationMLDescription& d) {
  Found f;
  for (const auto& item : d.items()) {
    f.parts += std::holds_alternative<twin::CreatePartItem>(item);
    f.links += std::holds_alternative<twin::ConnectionItem>(item);
  }
  return f;
}

std::string load_error(const std::filesystem::path& file) {
  sim::MeshCache cache;
  try {
    twin::load_product(file, cache);
  } catch (const twin::DescriptionError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("Part2.aml (CAEX 2.15, BOM, braced IDs, Frame attributes): a plant, not a product") {
  const twin::AutomationMLDescription d(kDir / "Part2.aml");
  CHECK(d.schema_version() == "2.15");
  const Found f = count_items(d);
  CHECK(f.parts > 0);
  CHECK(f.links == 1);
  CHECK_THAT(load_error(kDir / "Part2.aml"), Catch::Contains("Part2.aml:82") && Catch::Contains("has no coordinates"));
}

TEST_CASE("Test3_IH_IE_ExtInt.aml: two screwdrivers linked by an energy interface") {
  const twin::AutomationMLDescription d(kDir / "Test3_IH_IE_ExtInt.aml");
  const Found f = count_items(d);
  CHECK(f.parts == 2);
  CHECK(f.links == 1);
  CHECK_THAT(load_error(kDir / "Test3_IH_IE_ExtInt.aml"),
             Catch::Contains("InternalLink \"Link\"") && Catch::Contains("'EnergySupply'") && Catch::Contains("no coordinates"));
}

TEST_CASE("Test4_SUC_V3.aml (CAEX 3.0 class libraries only): no instances") {
  CHECK_THAT(load_error(kDir / "Test4_SUC_V3.aml"), Catch::Contains("no InstanceHierarchy"));
}

TEST_CASE("Topology_2021.aml: two unlinked elements") {
  const twin::AutomationMLDescription d(kDir / "Topology_2021.aml");
  const Found f = count_items(d);
  CHECK(f.parts == 2);
  CHECK(f.links == 0);
  CHECK_THAT(load_error(kDir / "Topology_2021.aml"), Catch::Contains("not reached by any link"));
}

TEST_CASE("the CAEX schemas are not products either") {
  for (const char* xsd : {"CAEX_ClassModel_V.3.0.xsd", "CAEX_ClassModel_V2.15.xsd"}) {
    CHECK_THROWS_WITH(twin::AutomationMLDescription(kDir / xsd), Catch::Contains("not a CAEX file"));
  }
}

int main(int argc, char** argv) {
  if (!std::filesystem::is_directory(kDir)) {
    std::cout << "skipped: " << kDir.string() << " is not there (../shared/ beside the clone)\n";
    return 77;
  }
  return Catch::Session().run(argc, argv);
}
