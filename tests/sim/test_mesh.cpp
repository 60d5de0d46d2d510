#include <catch2/catch.hpp>

#include "sim/mesh/triangle_mesh.hpp"

namespace {
std::filesystem::path data(const std::string& relative) { return std::filesystem::path(TEST_DATA_DIR) / relative; }
std::filesystem::path products(const std::string& relative) { return std::filesystem::path(PRODUCTS_DIR) / relative; }
}  // namespace

TEST_CASE("meshes load from OBJ and STL in metres", "[mesh]") {
  const auto plate = sim::load_mesh(data("good/meshes/plate.obj"));
  CHECK(plate->triangles.size() == 12);
  CHECK(plate->bounds.min().isApprox(Eigen::Vector3d(-0.02, 0, -0.02), 1e-6));
  CHECK(plate->bounds.max().isApprox(Eigen::Vector3d(0.02, 0.01, 0.02), 1e-6));

  const auto block = sim::load_mesh(data("good/meshes/block.stl"));
  CHECK(block->triangles.size() == 12);
  CHECK(block->bounds.sizes().isApprox(Eigen::Vector3d(0.01, 0.01, 0.01), 1e-6));
}

TEST_CASE("a mesh's objects are kept apart as convex pieces", "[mesh]") {
  const auto faceplate = sim::load_mesh(products("cranfield/meshes/faceplate.obj"));
  // 5 holes of 32 ring pieces each, plus the solid grid cells around them.
  CHECK(faceplate->pieces.size() > 5 * 32);
  CHECK(faceplate->bounds.sizes().isApprox(Eigen::Vector3d(0.240, 0.012, 0.180), 1e-6));
  std::size_t vertices = 0;
  for (const auto& piece : faceplate->pieces) vertices += piece.size();
  CHECK(vertices == faceplate->vertices.size());
}

TEST_CASE("a file that is not a mesh is a MeshError", "[mesh]") {
  CHECK_THROWS_AS(sim::load_mesh(data("bad/meshes/garbage.obj")), sim::MeshError);
  CHECK_THROWS_AS(sim::load_mesh(data("bad/meshes/none.obj")), sim::MeshError);
}

TEST_CASE("a CAD export in millimetres: unwelded binary STL, scaled to metres, welded, known convex", "[mesh]") {
  const auto block = sim::load_mesh(data("planning/units/meshes/block_mm.stl"), 1e-3);
  CHECK(block->triangles.size() == 12);
  CHECK(block->vertices.size() == 8);  // 36 corners as written, 8 once welded
  CHECK(block->bounds.min().isApprox(Eigen::Vector3d(-0.01, 0, -0.01), 1e-6));
  CHECK(block->bounds.max().isApprox(Eigen::Vector3d(0.01, 0.02, 0.01), 1e-6));
  CHECK(block->convex);

  sim::MeshCache cache;  // a file at two scales is two meshes
  CHECK(cache.get(data("planning/units/meshes/block_mm.stl"), 1e-3)->bounds.sizes().x() == Approx(0.02));
  CHECK(cache.get(data("planning/units/meshes/block_mm.stl"))->bounds.sizes().x() == Approx(20));
  CHECK(cache.size() == 2);
}

TEST_CASE("convexity: a box is convex, a frame of one piece and an open box are not", "[mesh]") {
  CHECK(sim::load_mesh(data("planning/backtrack/meshes/block.obj"))->convex);
  CHECK_FALSE(sim::load_mesh(data("planning/lipped-box/meshes/wall_left.obj"))->convex);
  CHECK_FALSE(sim::load_mesh(products("cranfield/meshes/faceplate.obj"))->convex);  // many pieces
}

TEST_CASE("a careless export: degenerate and duplicate triangles are dropped, open edges counted, all said",
          "[mesh][repairs]") {
  const auto block = sim::load_mesh(data("planning/messy/meshes/open_block_mm.stl"), 1e-3);
  CHECK(block->triangles.size() == 10);  // 12 written: a duplicate and a sliver dropped
  CHECK(block->repairs.degenerate == 1);
  CHECK(block->repairs.duplicate == 1);
  CHECK(block->repairs.open_edges == 4);  // around the missing top
  CHECK(block->repairs.non_manifold_edges == 0);
  CHECK_FALSE(block->convex);  // open: no volume to compare
  CHECK(block->repairs.describe() ==
        "1 degenerate triangle dropped; 1 duplicate triangle dropped; 4 open edges (the mesh is not closed)");
  CHECK_FALSE(sim::load_mesh(data("planning/units/meshes/block_mm.stl"), 1e-3)->repairs.any());
}

TEST_CASE("flipped normals: triangles wound against their neighbours, or a piece inside out, are turned and said",
          "[mesh][repairs]") {
  const auto volume = [](const sim::TriangleMesh& m) {
    double v = 0;
    for (const auto& t : m.triangles) v += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6;
    return v;
  };
  const auto flipped = sim::load_mesh(data("planning/messy/meshes/flipped_block_mm.obj"), 1e-3);
  CHECK(flipped->repairs.flipped == 2);
  CHECK(volume(*flipped) == Approx(8e-6));  // 20 mm cubed, outwards
  CHECK(flipped->convex);
  CHECK(flipped->repairs.describe() == "2 triangles turned to face outwards (their normals were flipped)");

  const auto inside_out = sim::load_mesh(data("planning/messy/meshes/inside_out_block_mm.obj"), 1e-3);
  CHECK(inside_out->repairs.flipped == 12);
  CHECK(volume(*inside_out) == Approx(8e-6));
  CHECK(inside_out->convex);
}
