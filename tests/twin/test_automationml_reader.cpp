#include <variant>

#include "tests/twin/test_support.hpp"
#include "twin/description/automationml/automationml_description.hpp"
#include "twin/description/automationml/caex_values.hpp"

using twin::Vec3;

TEST_CASE("paper-style CAEX 3.0: parts, types, attributes, links, meshes", "[aml]") {
  const twin::AutomationMLDescription description(test::data("good/paper_style.aml"));
  CHECK(description.schema_version() == "3.0");
  CHECK(description.product_name() == "Stack");
  CHECK(description.group_count() == 1);

  const auto loaded = test::load(test::data("good/paper_style.aml"));
  const twin::Product& product = loaded.product;
  REQUIRE(product.parts().size() == 3);
  REQUIRE(product.connections().size() == 2);

  const auto& base = test::part(product, "base");
  CHECK(twin::short_type_name(base.type) == "Plate");
  CHECK(base.color == "grey");                                // instance Value
  CHECK(test::part(product, "turned").color == "white");      // inherited class DefaultValue
  REQUIRE(base.mesh.has_value());
  CHECK(base.mesh->file.filename() == "plate.obj");
  CHECK(test::part(product, "block").mesh->file.filename() == "block.stl");

  const auto& link = product.connections()[1];
  CHECK(product.parts()[link.part1].name == "block");
  CHECK(link.interface1 == "top");
  CHECK(product.parts()[link.part2].name == "turned");
  CHECK(link.interface2 == "side");
}

TEST_CASE("paper-style product is placed by its links and orientations", "[aml][placement]") {
  const auto loaded = test::load(test::data("good/paper_style.aml"));
  CHECK_VEC3(test::position_mm(loaded.product, "base"), 0, 0, 0);
  CHECK_VEC3(test::position_mm(loaded.product, "block"), 20, 10, 0);
  // Turned 90 degrees about Y, its side interface (5, 0, 0) points to -Z.
  CHECK_VEC3(test::position_mm(loaded.product, "turned"), 20, 20, 5);
  const twin::Quat expected(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()));
  CHECK(test::part(loaded.product, "turned").final_pose.linear().isApprox(expected.toRotationMatrix(), 1e-9));
}

TEST_CASE("editor-style CAEX 2.15 gives the same product as the paper style", "[aml]") {
  // BOM, braced IDs in upper case, Frame attributes, instance interfaces with IDs, links by
  // bare interface ID, cm and m, an inherited interface overridden by the derived class,
  // an instance attribute moving an interface, an orientation from the instance's Frame.
  const twin::AutomationMLDescription description(test::data("good/editor_style.aml"));
  CHECK(description.schema_version() == "2.15");
  const auto editor = test::load(test::data("good/editor_style.aml"));
  const auto paper = test::load(test::data("good/paper_style.aml"));
  REQUIRE(editor.product.parts().size() == paper.product.parts().size());
  for (const auto& p : paper.product.parts()) {
    INFO(p.name);
    const auto& e = test::part(editor.product, p.name);
    CHECK(e.id == p.id);  // "{0A00...}" normalised to "0a00..."
    CHECK(e.final_pose.isApprox(p.final_pose, 1e-9));
    CHECK(e.color == p.color);
  }
  REQUIRE(editor.product.connections().size() == 2);
  for (std::size_t i = 0; i < 2; ++i) {
    CHECK(editor.product.connections()[i].interface1 == paper.product.connections()[i].interface1);
    CHECK(editor.product.connections()[i].interface2 == paper.product.connections()[i].interface2);
  }
}

TEST_CASE("the description yields the paper's create, parameter and connection items", "[aml]") {
  const twin::AutomationMLDescription description(test::data("good/paper_style.aml"));
  int creates = 0, parameters = 0, connections = 0;
  for (const auto& item : description.items()) {
    if (std::holds_alternative<twin::CreatePartItem>(item)) ++creates;
    if (std::holds_alternative<twin::ParameterItem>(item)) ++parameters;
    if (std::holds_alternative<twin::ConnectionItem>(item)) ++connections;
  }
  CHECK(creates == 3);
  CHECK(parameters == 6);  // Plate: slot, mesh; Block: bottom, top, side, mesh
  CHECK(connections == 2);
}

TEST_CASE("lengths: m, cm, mm, and metres when no unit is given", "[aml][units]") {
  const twin::SourceRef here{"units.aml", 1, "Attribute"};
  CHECK(twin::aml::length_unit_scale("", here) == 1.0);
  CHECK(twin::aml::length_unit_scale("m", here) == 1.0);
  CHECK(twin::aml::length_unit_scale("cm", here) == 0.01);
  CHECK(twin::aml::length_unit_scale("mm", here) == 0.001);
  CHECK_THROWS_WITH(twin::aml::length_unit_scale("furlong", here), Catch::Contains("unknown length unit 'furlong'"));

  const Vec3 v = twin::aml::parse_vec3(" 1.5, -2 ,+3e1 ", 0.001, here);
  CHECK(v.isApprox(Vec3(0.0015, -0.002, 0.03)));
  CHECK_THROWS_WITH(twin::aml::parse_vec3("1,2,3,4", 1, here), Catch::Contains("not three numbers"));
  CHECK_THROWS_WITH(twin::aml::parse_vec3("1,,3", 1, here), Catch::Contains("not a finite number"));
  CHECK_THROWS_WITH(twin::aml::parse_vec3("1,nan,3", 1, here), Catch::Contains("not a finite number"));
}

TEST_CASE("the AutomationML Frame: rx, then ry, then rz about fixed axes, in degrees", "[aml][frame]") {
  const twin::Quat q = twin::rotation_from_xyz_degrees(Vec3(90, 0, 90));
  // X then Z about fixed axes: the part's Y axis goes to Z by rx, then stays Z under rz.
  CHECK((q * Vec3::UnitY()).isApprox(Vec3::UnitZ(), 1e-12));
  // its X axis is untouched by rx and turned to Y by rz.
  CHECK((q * Vec3::UnitX()).isApprox(Vec3::UnitY(), 1e-12));
}

namespace {

// A second format, in memory: what a STEP or JSON reader would hand the builder.
class InMemoryDescription : public twin::ProductDescription {
 public:
  std::string product_name() const override { return "pair"; }
  std::filesystem::path source() const override { return "memory"; }
  std::vector<twin::DescriptionItem> items() const override {
    twin::ParameterItem socket{"Base", "socket", twin::Frame{Vec3(0, 0.01, 0), twin::Quat::Identity()}, {}, {}};
    twin::ParameterItem pin{"Pin", "end", twin::Frame{Vec3(0, -0.002, 0), twin::Quat::Identity()}, {}, {}};
    twin::CreatePartItem base;
    base.id = "b";
    base.name = "base";
    base.type = "Base";
    twin::CreatePartItem p;
    p.id = "p";
    p.name = "pin";
    p.type = "Pin";
    twin::ConnectionItem c{"b", "socket", "p", "end", "base-pin", {}};
    return {c, base, p, socket, pin};  // any order: connections are applied last
  }
};

}  // namespace

TEST_CASE("another description format needs no change to the model", "[model]") {
  twin::Product product = twin::build_product(InMemoryDescription());
  twin::place_parts(product);
  CHECK_VEC3(test::position_mm(product, "pin"), 0, 12, 0);
}

TEST_CASE("products are independent objects, not global state", "[model]") {
  const auto a = test::load(test::data("good/paper_style.aml"));
  const auto b = test::load(test::product("cranfield/cranfield.aml"));
  const auto again = test::load(test::data("good/paper_style.aml"));
  CHECK(a.product.types().count("Parts/Block") == 1);
  CHECK(b.product.types().count("Parts/Block") == 0);
  CHECK(again.product.parts()[2].final_pose.isApprox(a.product.parts()[2].final_pose));
}
