#pragma once
// Paths and helpers shared by the twin tests.

#include <filesystem>
#include <string>

#include <catch2/catch.hpp>

#include "sim/mesh/triangle_mesh.hpp"
#include "tests/support/paths.hpp"
#include "twin/geometry/product_loader.hpp"
#include "twin/planning/assembly_planner.hpp"
#include "twin/planning/path_planner.hpp"
#include "twin/planning/sequence_planner.hpp"

namespace test {

// Whether the plan has a finding of this kind whose message contains the fragment.
inline bool has_finding(const twin::Plan& plan, const std::string& kind, const std::string& fragment) {
  for (const auto& f : plan.findings) {
    if (f.kind == kind && f.message.find(fragment) != std::string::npos) return true;
  }
  return false;
}

inline twin::LoadedProduct load(const std::filesystem::path& file) {
  sim::MeshCache cache;
  return twin::load_product(file, cache);
}

// A product loaded and planned as the twin plans it (search, linear); the mesh cache lives
// as long as the product that points into it.
struct Planned {
  explicit Planned(const std::filesystem::path& file, const twin::PlannerOptions& options = {})
      : product(twin::load_product(file, meshes)), plan(plan_of(product, options)) {}
  static twin::Plan plan_of(const twin::LoadedProduct& product, const twin::PlannerOptions& options = {}) {
    auto sequence = twin::make_sequence_planner("search");
    return twin::plan_assembly(product, *sequence, *twin::make_path_planner("linear"), options);
  }
  sim::MeshCache meshes;
  twin::LoadedProduct product;
  twin::Plan plan;
};

// Planning for a cell with fixtures (deploy/cells/default.yaml): the nested Cranfield's shaft
// and pendulum, built aside, stand on nothing (the pendulum's arm tips them over) until they
// go in; the cell's jig holds them.
inline twin::PlannerOptions with_fixtures() {
  twin::PlannerOptions options;
  options.fixtures = true;
  return options;
}

inline const twin::DigitalPart& part(const twin::Product& product, const std::string& name) {
  const auto index = product.find_part_by_name(name);
  REQUIRE(index.has_value());
  return product.parts()[*index];
}

// Final position in millimetres, which is what the product files and docs speak in.
inline twin::Vec3 position_mm(const twin::Product& product, const std::string& name) {
  return part(product, name).final_pose.translation() * 1000.0;
}

}  // namespace test

#define CHECK_VEC3(actual, ex, ey, ez)                     \
  do {                                                  \
    const twin::Vec3 v_ = (actual);                     \
    CHECK(v_.x() == Approx(ex).margin(1e-6));            \
    CHECK(v_.y() == Approx(ey).margin(1e-6));            \
    CHECK(v_.z() == Approx(ez).margin(1e-6));            \
  } while (0)
