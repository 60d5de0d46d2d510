// Finished-product geometry (paper Fig. 4) against positions computed by hand from
// docs/products.md.

#include "tests/twin/test_support.hpp"

namespace {

// Part bounds in the finished product, mm.
Eigen::AlignedBox3d bounds_mm(const twin::LoadedProduct& loaded, const std::string& name) {
  const auto index = *loaded.product.find_part_by_name(name);
  Eigen::AlignedBox3d box;
  for (const auto& v : loaded.meshes[index]->vertices) box.extend(loaded.product.parts()[index].final_pose * v * 1000.0);
  return box;
}

double lowest_mm(const twin::LoadedProduct& loaded) {
  double lowest = 1e9;
  for (const auto& p : loaded.product.parts()) lowest = std::min(lowest, bounds_mm(loaded, p.name).min().y());
  return lowest;
}

}  // namespace

TEST_CASE("Cranfield: every part at its hand-computed place", "[placement][cranfield]") {
  const auto loaded = test::load(test::product("cranfield/cranfield.aml"));
  const auto& product = loaded.product;
  REQUIRE(product.parts().size() == 9);
  CHECK(product.connections().size() == 13);

  CHECK_VEC3(test::position_mm(product, "back"), 0, 0, 0);
  CHECK_VEC3(test::position_mm(product, "shaft"), 0, 0, 14);
  CHECK_VEC3(test::position_mm(product, "pendulum"), 0, 12, 14);
  CHECK_VEC3(test::position_mm(product, "boltA1"), -40, 0, 69);
  CHECK_VEC3(test::position_mm(product, "boltA2"), 40, 0, 69);
  CHECK_VEC3(test::position_mm(product, "boltR1"), -61, 0, -46);
  CHECK_VEC3(test::position_mm(product, "boltR2"), 61, 0, -46);
  CHECK_VEC3(test::position_mm(product, "separator"), 0, 12, 69);
  CHECK_VEC3(test::position_mm(product, "front"), 0, 78, 0);
  CHECK(lowest_mm(loaded) == Approx(0).margin(1e-6));
}

TEST_CASE("Cranfield: the shaft and each peg stand in their holes with clearance", "[placement][cranfield]") {
  const auto loaded = test::load(test::product("cranfield/cranfield.aml"));
  // Hole centres on the faceplates (x, z) and the hole half-size: 8 mm (16 mm holes).
  const struct {
    const char* part;
    double x, z;
  } holes[] = {{"shaft", 0, 14}, {"boltA1", -40, 69}, {"boltA2", 40, 69}, {"boltR1", -61, -46}, {"boltR2", 61, -46}};
  const auto back = bounds_mm(loaded, "back");
  const auto front = bounds_mm(loaded, "front");
  for (const auto& h : holes) {
    INFO(h.part);
    const auto peg = bounds_mm(loaded, h.part);
    // 15 mm across, centred on a 16 mm hole: 0.5 mm free on every side.
    CHECK(peg.min().x() == Approx(h.x - 7.5).margin(1e-6));
    CHECK(peg.max().x() == Approx(h.x + 7.5).margin(1e-6));
    CHECK(peg.min().z() == Approx(h.z - 7.5).margin(1e-6));
    CHECK(peg.max().z() == Approx(h.z + 7.5).margin(1e-6));
    // Through both plates: flush with the back's bottom and the front's top.
    CHECK(peg.min().y() == Approx(back.min().y()).margin(1e-6));
    CHECK(peg.max().y() == Approx(front.max().y()).margin(1e-6));
  }
  // The pendulum and the separator lie on the back plate, under the front plate.
  CHECK(bounds_mm(loaded, "pendulum").min().y() == Approx(back.max().y()).margin(1e-6));
  CHECK(bounds_mm(loaded, "separator").min().y() == Approx(back.max().y()).margin(1e-6));
  CHECK(bounds_mm(loaded, "separator").max().y() < front.min().y());
}

TEST_CASE("Lego tower: bricks on the stud grid, one brick hanging under the overhang", "[placement][lego]") {
  const auto loaded = test::load(test::product("lego-tower/lego-tower.aml"));
  const auto& product = loaded.product;
  REQUIRE(product.parts().size() >= 10);
  CHECK(lowest_mm(loaded) == Approx(0).margin(1e-6));
  CHECK_VEC3(test::position_mm(product, "B1"), 0, 0, 0);
  CHECK_VEC3(test::position_mm(product, "B3"), -8, 9.6, 8);  // a 2x4 turned 90 degrees
  CHECK_VEC3(test::position_mm(product, "overhang"), 16, 28.8, 8);
  CHECK_VEC3(test::position_mm(product, "hanging"), 24, 19.2, 8);
  CHECK_VEC3(test::position_mm(product, "B9"), 0, 38.4, 8);

  // Nothing is under the hanging brick: it can only come from the side or from below.
  const auto hanging = bounds_mm(loaded, "hanging");
  const auto overhang = bounds_mm(loaded, "overhang");
  CHECK(hanging.max().y() == Approx(overhang.min().y()).margin(1e-6));
  for (const auto& p : product.parts()) {
    if (p.name == "hanging") continue;
    const auto other = bounds_mm(loaded, p.name);
    const bool overlaps_xz = other.min().x() < hanging.max().x() - 1e-6 && other.max().x() > hanging.min().x() + 1e-6 &&
                             other.min().z() < hanging.max().z() - 1e-6 && other.max().z() > hanging.min().z() + 1e-6;
    if (overlaps_xz) CHECK(other.min().y() >= hanging.max().y() - 1e-6);
  }
}

namespace {

twin::Product two_paths(double error_m) {
  // a -> b directly, and a -> c -> b: a loop that is off by error_m along X.
  twin::Product product("loop", "memory");
  const twin::Frame origin{};
  product.set_type_interface("T", "o", origin);
  product.set_type_interface("T", "x", twin::Frame{twin::Vec3(0.01, 0, 0), twin::Quat::Identity()});
  product.set_type_interface("T", "y", twin::Frame{twin::Vec3(0, 0.01, 0), twin::Quat::Identity()});
  product.set_type_interface("T", "xy", twin::Frame{twin::Vec3(0.01 + error_m, 0.01, 0), twin::Quat::Identity()});
  for (const char* id : {"a", "b", "c"}) {
    twin::DigitalPart p;
    p.id = p.name = id;
    p.type = "T";
    product.add_part(p);
  }
  product.connect("a", "xy", "b", "o", "a-b", {"memory", 7, "InternalLink \"a-b\""});
  product.connect("a", "x", "c", "o", "a-c", {"memory", 8, "InternalLink \"a-c\""});
  product.connect("c", "y", "b", "o", "c-b", {"memory", 9, "InternalLink \"c-b\""});
  return product;
}

}  // namespace

TEST_CASE("links that close a loop must agree within the tolerance", "[placement][loop]") {
  twin::Product within = two_paths(0.00005);  // 0.05 mm: under the default 0.1 mm
  CHECK_NOTHROW(twin::place_parts(within));

  twin::Product off = two_paths(0.001);
  CHECK_THROWS_WITH(twin::place_parts(off), Catch::Contains("c-b") && Catch::Contains("loop that does not fit") &&
                                                Catch::Contains("1.000000 mm apart"));

  twin::Product strict = two_paths(0.00005);
  CHECK_THROWS(twin::place_parts(strict, twin::PlacementOptions{0.00001}));
}
