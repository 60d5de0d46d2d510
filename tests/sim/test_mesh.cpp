#include <fstream>
#include <limits>
#include <regex>
#include <unistd.h>

#include <catch2/catch.hpp>

#include "sim/mesh/mesh_disk_cache.hpp"
#include "sim/mesh/triangle_mesh.hpp"
#include "tests/support/paths.hpp"

TEST_CASE("meshes load from OBJ and STL in metres", "[mesh]") {
  const auto plate = sim::load_mesh(test::data("good/meshes/plate.obj"));
  CHECK(plate->triangles.size() == 12);
  CHECK(plate->bounds.min().isApprox(Eigen::Vector3d(-0.02, 0, -0.02), 1e-6));
  CHECK(plate->bounds.max().isApprox(Eigen::Vector3d(0.02, 0.01, 0.02), 1e-6));

  const auto block = sim::load_mesh(test::data("good/meshes/block.stl"));
  CHECK(block->triangles.size() == 12);
  CHECK(block->bounds.sizes().isApprox(Eigen::Vector3d(0.01, 0.01, 0.01), 1e-6));
}

TEST_CASE("a mesh's objects are kept apart as convex pieces", "[mesh]") {
  const auto faceplate = sim::load_mesh(test::product("cranfield/meshes/faceplate.obj"));
  // 5 holes of 32 ring pieces each, plus the solid grid cells around them.
  CHECK(faceplate->pieces.size() > 5 * 32);
  CHECK(faceplate->bounds.sizes().isApprox(Eigen::Vector3d(0.240, 0.012, 0.180), 1e-6));
  std::size_t vertices = 0;
  for (const auto& piece : faceplate->pieces) vertices += piece.size();
  CHECK(vertices == faceplate->vertices.size());
}

TEST_CASE("a piece's hull is made of its outer corners only", "[mesh]") {
  // A bearing: a ring whose bore's vertices lie inside its hull.
  const auto bearing = sim::load_mesh(test::data("planning/shaft-bearing/meshes/bearing.obj"), 1e-3);
  REQUIRE(bearing->pieces.size() == 1);
  REQUIRE(bearing->hull_corners.size() == 1);
  const auto& corners = bearing->hull_corners[0];
  CHECK(corners.size() < bearing->pieces[0].size());
  const Eigen::Vector3d centre = bearing->bounds.center();
  double inner = std::numeric_limits<double>::infinity();
  for (auto v : bearing->pieces[0]) {
    const Eigen::Vector3d d = bearing->vertices[v] - centre;
    inner = std::min(inner, Eigen::Vector2d(d.x(), d.z()).norm());
  }
  for (auto v : corners) {
    const Eigen::Vector3d d = bearing->vertices[v] - centre;
    CHECK(Eigen::Vector2d(d.x(), d.z()).norm() > inner + 1e-4);  // none from the bore
  }
  // A box: all eight.
  const auto block = sim::load_mesh(test::data("planning/messy/meshes/flipped_block_mm.obj"), 1e-3);
  CHECK(block->hull_corners.at(0).size() == 8);
}

TEST_CASE("a file that is not a mesh is a MeshError", "[mesh]") {
  CHECK_THROWS_AS(sim::load_mesh(test::data("bad/meshes/garbage.obj")), sim::MeshError);
  CHECK_THROWS_AS(sim::load_mesh(test::data("bad/meshes/none.obj")), sim::MeshError);
}

TEST_CASE("a CAD export in millimetres: unwelded binary STL, scaled to metres, welded, known convex", "[mesh]") {
  const auto block = sim::load_mesh(test::data("planning/units/meshes/block_mm.stl"), 1e-3);
  CHECK(block->triangles.size() == 12);
  CHECK(block->vertices.size() == 8);  // 36 corners as written, 8 once welded
  CHECK(block->bounds.min().isApprox(Eigen::Vector3d(-0.01, 0, -0.01), 1e-6));
  CHECK(block->bounds.max().isApprox(Eigen::Vector3d(0.01, 0.02, 0.01), 1e-6));
  CHECK(block->convex);

  sim::MeshCache cache;  // a file at two scales is two meshes
  CHECK(cache.get(test::data("planning/units/meshes/block_mm.stl"), 1e-3)->bounds.sizes().x() == Approx(0.02));
  CHECK(cache.get(test::data("planning/units/meshes/block_mm.stl"))->bounds.sizes().x() == Approx(20));
  CHECK(cache.size() == 2);
}

TEST_CASE("convexity: a box is convex, a frame of one piece and an open box are not", "[mesh]") {
  CHECK(sim::load_mesh(test::data("planning/backtrack/meshes/block.obj"))->convex);
  CHECK_FALSE(sim::load_mesh(test::data("planning/lipped-box/meshes/wall_left.obj"))->convex);
  CHECK_FALSE(sim::load_mesh(test::product("cranfield/meshes/faceplate.obj"))->convex);  // many pieces
}

TEST_CASE("a careless export: degenerate and duplicate triangles are dropped, open edges counted, all said",
          "[mesh][repairs]") {
  const auto block = sim::load_mesh(test::data("planning/messy/meshes/open_block_mm.stl"), 1e-3);
  CHECK(block->triangles.size() == 10);  // 12 written: a duplicate and a sliver dropped
  CHECK(block->repairs.degenerate == 1);
  CHECK(block->repairs.duplicate == 1);
  CHECK(block->repairs.open_edges == 4);  // around the missing top
  CHECK(block->repairs.non_manifold_edges == 0);
  CHECK_FALSE(block->convex);  // open: no volume to compare
  CHECK(block->repairs.describe() ==
        "1 degenerate triangle dropped; 1 duplicate triangle dropped; 4 open edges (the mesh is not closed)");
  CHECK_FALSE(sim::load_mesh(test::data("planning/units/meshes/block_mm.stl"), 1e-3)->repairs.any());
}

TEST_CASE("T-junctions: an edge run whole past a neighbour's corner is split there, and the mesh is closed",
          "[mesh][repairs]") {
  const auto block = sim::load_mesh(test::data("planning/messy/meshes/t_junction_block_mm.obj"), 1e-3);
  CHECK(block->repairs.t_junctions == 2);
  CHECK(block->repairs.open_edges == 0);
  CHECK(block->triangles.size() == 16);  // the front's and back's top triangles split in two
  double volume = 0;
  for (const auto& t : block->triangles) {
    volume += block->vertices[t[0]].dot(block->vertices[t[1]].cross(block->vertices[t[2]])) / 6;
  }
  CHECK(volume == Approx(8e-6));  // the same cube, outwards
  CHECK(block->convex);
  CHECK(block->repairs.describe() == "2 edges split at corners that lay on them (T-junctions)");
  // An open edge with no corner on it stays open.
  CHECK(sim::load_mesh(test::data("planning/messy/meshes/open_block_mm.stl"), 1e-3)->repairs.t_junctions == 0);
  // A real one: FurnitureBench's cabinet door (tests/data/real), three bodies welded into one,
  // read as 24 open edges before.
  const auto door = sim::load_mesh(std::filesystem::path(REAL_DATA_DIR) / "fb-cabinet/meshes/cabinet_door_right.obj");
  CHECK(door->repairs.t_junctions == 8);
  CHECK(door->repairs.open_edges == 0);
}

TEST_CASE("a hole of three edges is closed by the triangle missing there, a hole of four is not", "[mesh][repairs]") {
  const auto block = sim::load_mesh(test::data("planning/messy/meshes/missing_triangle_block_mm.obj"), 1e-3);
  CHECK(block->repairs.missing_triangles == 1);
  CHECK(block->repairs.open_edges == 0);
  CHECK(block->repairs.flipped == 0);  // filled wound as its neighbours are
  CHECK(block->convex);
  CHECK(block->repairs.describe() == "1 missing triangle filled (a hole of three edges)");
  // A hole of four edges (the open box's missing top) is left open.
  const auto open_box = sim::load_mesh(test::data("planning/messy/meshes/open_block_mm.stl"), 1e-3);
  CHECK(open_box->repairs.missing_triangles == 0);
  CHECK(open_box->repairs.open_edges == 4);
}

TEST_CASE("T-junctions: a file of many open corners in one plane is read in bounded time, left open", "[mesh][repairs]") {
  // 20 000 loose triangles at x = 0: every open edge's corners share its x, so looking for
  // corners on each edge by x alone would be 60 000 squared checks.
  const auto file = std::filesystem::temp_directory_path() / ("loose-" + std::to_string(::getpid()) + ".obj");
  {
    std::ofstream out(file);
    for (int i = 0; i < 20000; ++i) {
      const double y = (i % 200) * 2e-3, z = (i / 200) * 2e-3;
      out << "v 0 " << y << ' ' << z << "\nv 0 " << y + 1e-3 << ' ' << z << "\nv 0 " << y << ' ' << z + 1e-3 << '\n';
    }
    for (int i = 0; i < 20000; ++i) out << "f " << 3 * i + 1 << ' ' << 3 * i + 2 << ' ' << 3 * i + 3 << '\n';
  }
  const auto loose = sim::load_mesh(file, 1);
  std::filesystem::remove(file);
  CHECK(loose->repairs.open_edges == 60000);
  CHECK(loose->repairs.t_junctions == 0);
  CHECK(loose->repairs.missing_triangles == 0);  // each hole's three edges are one triangle's own
}

TEST_CASE("an edge shared by more than two triangles is counted and said", "[mesh][repairs]") {
  const auto fins = sim::load_mesh(test::data("planning/messy/meshes/fins_mm.obj"), 1e-3);
  CHECK(fins->triangles.size() == 3);
  CHECK(fins->repairs.non_manifold_edges == 1);
  CHECK(fins->repairs.open_edges == 6);
  CHECK_FALSE(fins->convex);
  CHECK_THAT(fins->repairs.describe(), Catch::Contains("1 edge shared by more than two triangles"));
}

TEST_CASE("flipped normals: triangles wound against their neighbours, or a piece inside out, are turned and said",
          "[mesh][repairs]") {
  const auto volume = [](const sim::TriangleMesh& m) {
    double v = 0;
    for (const auto& t : m.triangles) v += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6;
    return v;
  };
  const auto flipped = sim::load_mesh(test::data("planning/messy/meshes/flipped_block_mm.obj"), 1e-3);
  CHECK(flipped->repairs.flipped == 2);
  CHECK(volume(*flipped) == Approx(8e-6));  // 20 mm cubed, outwards
  CHECK(flipped->convex);
  CHECK(flipped->repairs.describe() == "2 triangles turned to face outwards (their normals were flipped)");

  const auto inside_out = sim::load_mesh(test::data("planning/messy/meshes/inside_out_block_mm.obj"), 1e-3);
  CHECK(inside_out->repairs.flipped == 12);
  CHECK(volume(*inside_out) == Approx(8e-6));
  CHECK(inside_out->convex);
}

TEST_CASE("the disk cache gives back the mesh as loaded, by content, and ignores a broken entry", "[mesh][cache]") {
  const auto folder = std::filesystem::temp_directory_path() / ("mesh-cache-" + std::to_string(::getpid()));
  std::filesystem::remove_all(folder);
  const auto file = test::data("planning/messy/meshes/flipped_block_mm.obj");
  const auto loaded = sim::load_mesh(file, 1e-3);
  const auto same = [&](const sim::TriangleMesh& m) {
    CHECK(m.vertices == loaded->vertices);
    CHECK(m.triangles == loaded->triangles);
    CHECK(m.pieces == loaded->pieces);
    CHECK(m.hull_corners == loaded->hull_corners);
    CHECK(m.bvh_nodes == loaded->bvh_nodes);
    CHECK(m.bounds.isApprox(loaded->bounds));
    CHECK(m.convex == loaded->convex);
    CHECK(m.repairs.describe() == loaded->repairs.describe());
  };
  same(*sim::MeshCache(folder).get(file, 1e-3));  // loaded and written
  REQUIRE(std::distance(std::filesystem::directory_iterator(folder), {}) == 1);
  const auto entry = std::filesystem::directory_iterator(folder)->path();
  same(*sim::MeshDiskCache(folder).load(file, 1e-3));  // read back

  // Another scale is another entry; so is another content.
  sim::MeshCache(folder).get(file, 1.0);
  sim::MeshCache(folder).get(test::data("planning/messy/meshes/inside_out_block_mm.obj"), 1e-3);
  CHECK(std::distance(std::filesystem::directory_iterator(folder), {}) == 3);

  // A cut entry is not used: the mesh is loaded again and the entry written whole.
  const auto whole = std::filesystem::file_size(entry);
  std::filesystem::resize_file(entry, whole / 2);
  same(*sim::MeshDiskCache(folder).load(file, 1e-3));
  CHECK(std::filesystem::file_size(entry) == whole);
  // So is one whose triangles name vertices it does not have.
  {
    std::fstream f(entry, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(8 + 4 + 8 + 8 * 3 * 8 + 8);  // magic, version, vertex count, 8 vertices, triangle count
    const std::uint32_t far = 1000;
    f.write(reinterpret_cast<const char*>(&far), sizeof far);
  }
  same(*sim::MeshDiskCache(folder).load(file, 1e-3));
  // So is one with a simplified hull and no pieces (its hull's corners would be asked of none).
  {
    std::ifstream in(entry, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    const std::size_t lists = 8 + 4 + 8 + 8 * 3 * 8 + 8 + 12 * 3 * 4;  // up to the piece count
    const std::size_t corner_list = 8 + 8 + 8 * 4;  // one list of the block's 8 corners
    REQUIRE(loaded->pieces.size() == 1);
    REQUIRE(loaded->coarse_corners.empty());
    std::string damaged = bytes.substr(0, lists);
    const auto put = [&](std::uint64_t n, std::size_t size) { damaged.append(reinterpret_cast<const char*>(&n), size); };
    put(0, 8);  // no pieces
    put(0, 8);  // no hull corners
    put(1, 8);  // coarse corners: the 8 of the block
    put(8, 8);
    for (std::uint32_t v = 0; v < 8; ++v) put(v, 4);
    damaged += bytes.substr(lists + 2 * corner_list + 16);
    std::ofstream(entry, std::ios::binary | std::ios::trunc) << damaged;
  }
  same(*sim::MeshDiskCache(folder).load(file, 1e-3));
  // Entries are named by the SHA-256 of the content (64 hex digits), not by a hash one can
  // collide on purpose: meshes come from OEMs.
  CHECK(std::regex_match(entry.filename().string(), std::regex("[0-9a-f]{64}-.*\\.mesh")));
  std::filesystem::remove_all(folder);
}

TEST_CASE("the cache in memory: a second ask for a mesh is the same mesh, not loaded again", "[mesh][cache]") {
  const auto folder = std::filesystem::temp_directory_path() / ("mesh-memory-" + std::to_string(::getpid()));
  std::filesystem::remove_all(folder);
  sim::MeshCache cache(folder);
  const auto file = test::data("planning/messy/meshes/flipped_block_mm.obj");
  const auto first = cache.get(file, 1e-3);
  std::filesystem::remove_all(folder);  // nothing on disk: a second load would have to parse the file again
  CHECK(cache.get(file, 1e-3) == first);
  CHECK(cache.size() == 1);
  CHECK(cache.get(file, 1.0) != first);  // another scale, another mesh
  CHECK(cache.size() == 2);
  std::filesystem::remove_all(folder);
}

TEST_CASE("COLLADA: the file's own unit is applied, its up axis is not (coordinates as written)", "[mesh][units]") {
  // A 20 mm cube from 0 to 20 mm on each axis, <unit meter="0.001">, declared Y up and Z up.
  for (const char* file : {"planning/collada/meshes/block_mm_y_up.dae", "planning/collada/meshes/block_mm_z_up.dae"}) {
    INFO(file);
    const auto block = sim::load_mesh(test::data(file));
    CHECK(block->triangles.size() == 12);
    CHECK(block->bounds.min().isApprox(Eigen::Vector3d::Zero(), 1e-9));
    CHECK(block->bounds.max().isApprox(Eigen::Vector3d(0.02, 0.02, 0.02), 1e-6));
    CHECK(block->convex);
  }
}

TEST_CASE("a coarse hull holds every corner of the mesh: a real CAD post with rounded edges", "[mesh]") {
  // The post of ASAP's beam frame (tests/data/real), 4 904 triangles, 483 hull corners. Its
  // coarse hull is 256 of them grown to hold the rest. Bullet's GJK, which measured that,
  // answered eight of the corners with infinity: the hull grew by 3e35 m, and every
  // collision of the post, and of a beam coming down over it, went unseen.
  const auto file = std::filesystem::path(REAL_DATA_DIR) / "asap-beam-frame/meshes/2.obj";
  const auto mesh = sim::load_mesh(file, 0.01);
  REQUIRE(mesh->hull_corners.size() == 1);
  REQUIRE(mesh->coarse_corners.size() == sim::kCoarseCorners);
  CHECK(mesh->coarse_margin < 1e-4);
  CHECK(sim::farthest_outside(*mesh, mesh->coarse_corners, mesh->hull_corners[0]) <= mesh->coarse_margin);
  CHECK(sim::farthest_outside(*mesh, mesh->hull_corners[0], mesh->hull_corners[0]) == 0);
}

TEST_CASE("how far points lie outside a hull: beyond a face, an edge, a corner, and 0 inside or on it", "[mesh]") {
  sim::TriangleMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
  const std::vector<std::uint32_t> cube{0, 1, 2, 3, 4, 5, 6, 7};
  const auto outside = [&](const Eigen::Vector3d& p) {
    m.vertices.push_back(p);
    const double d = sim::farthest_outside(m, cube, {static_cast<std::uint32_t>(m.vertices.size() - 1)});
    m.vertices.pop_back();
    return d;
  };
  CHECK(outside({3, 0, 0}) == Approx(2));
  CHECK(outside({2, 2, 0}) == Approx(std::sqrt(2.0)));
  CHECK(outside({2, 2, 2}) == Approx(std::sqrt(3.0)));
  CHECK(outside({0.5, 0, 0}) == 0);
  CHECK(outside({1, 0.3, -0.2}) == 0);
  CHECK(sim::farthest_outside(m, cube, cube) == 0);
}

TEST_CASE("objects that are not convex pieces are joined into one piece, welded: a CAD export of a face per object",
          "[mesh]") {
  // The beam of tests/data/planning/beam-frame written with every face an object of its own,
  // each with its own copies of the corners. Taken as convex pieces, each face would be a flat
  // hull, and a part could pass through the beam between them.
  const auto mesh = sim::load_mesh(test::data("planning/beam-frame/meshes/beam_faces.obj"), 0.001);
  CHECK(mesh->pieces.size() == 1);
  CHECK(mesh->repairs.joined_objects == 12);
  CHECK(mesh->repairs.open_edges == 0);  // welded where the faces meet: closed
  CHECK_FALSE(mesh->convex);
  CHECK(sim::loading_report(*mesh).find("12 objects that are not convex pieces joined into one") != std::string::npos);
  // An authored decomposition stays as it is.
  const auto faceplate = sim::load_mesh(test::product("cranfield/meshes/faceplate.obj"), 1);
  CHECK(faceplate->pieces.size() > 1);
  CHECK(faceplate->repairs.joined_objects == 0);
}

TEST_CASE("a vendor's STL with a normal per triangle is welded by position: closed", "[mesh]") {
  // A cube as a binary STL whose every triangle carries its face's normal (a bearing from a
  // catalogue came in so with 10 512 open edges: corners that differ by their normals were
  // kept apart).
  const auto file = std::filesystem::temp_directory_path() / ("normals-" + std::to_string(::getpid()) + ".stl");
  {
    std::ofstream out(file, std::ios::binary);
    out.write(std::string(80, ' ').data(), 80);
    const std::uint32_t count = 12;
    out.write(reinterpret_cast<const char*>(&count), 4);
    const auto corner = [](int i) { return Eigen::Vector3f(i & 1 ? 1.f : 0.f, i & 2 ? 1.f : 0.f, i & 4 ? 1.f : 0.f); };
    for (const auto& f : std::vector<std::array<int, 4>>{{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}}) {
      for (const auto& t : {std::array<int, 3>{f[0], f[1], f[2]}, std::array<int, 3>{f[0], f[2], f[3]}}) {
        const Eigen::Vector3f n = (corner(t[1]) - corner(t[0])).cross(corner(t[2]) - corner(t[0])).normalized();
        out.write(reinterpret_cast<const char*>(n.data()), 12);
        for (int c : t) out.write(reinterpret_cast<const char*>(corner(c).eval().data()), 12);
        const std::uint16_t attributes = 0;
        out.write(reinterpret_cast<const char*>(&attributes), 2);
      }
    }
  }
  const auto cube = sim::load_mesh(file, 1);
  std::filesystem::remove(file);
  CHECK(cube->vertices.size() == 8);
  CHECK(cube->repairs.open_edges == 0);
  CHECK(cube->convex);
}
