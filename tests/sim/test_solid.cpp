// sim::deepest_inside and the flat regions that let it give up a piece lying on a flat face:
// against the depth of points sampled over the triangle, on solids with holes, an inner step
// and a ring, where a shadow leaving its region is what must not be missed.

#include <random>

#include <catch2/catch.hpp>

#include "sim/mesh/solid.hpp"
#include "tests/support/generated_products.hpp"
#include "tests/support/meshes.hpp"
#include "tests/support/sanitizers.hpp"

namespace {

using Triangle = std::array<Eigen::Vector3d, 3>;

// An L along z, `depth` deep: a low step (x 0..2a, y 0..a) and a tall block beside it (x 0..a,
// y 0..2a), its outline fanned from the inner corner. One closed piece, outwards.
sim::TriangleMesh l_block(double a, double depth) {
  const std::vector<Eigen::Vector2d> outline{{a, a}, {a, 2 * a}, {0, 2 * a}, {0, 0}, {2 * a, 0}, {2 * a, a}};
  sim::TriangleMesh m;
  m.pieces.emplace_back();
  for (const double z : {0.0, depth}) {
    for (const auto& p : outline) m.vertices.emplace_back(p.x(), p.y(), z);
  }
  const auto n = static_cast<std::uint32_t>(outline.size());
  for (std::uint32_t i = 1; i + 1 < n; ++i) {
    m.triangles.push_back({0, i + 1, i});          // z = 0, facing -z
    m.triangles.push_back({n, n + i, n + i + 1});  // z = depth, facing +z
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t j = (i + 1) % n;
    m.triangles.push_back({i, j, n + j});
    m.triangles.push_back({i, n + j, n + i});
  }
  for (std::uint32_t i = 0; i < m.vertices.size(); ++i) {
    m.pieces.back().push_back(i);
    m.bounds.extend(m.vertices[i]);
  }
  return m;
}

// A plate 200 x 60 mm, 10 mm thick (its top at y = 0.01), with three rectangular holes.
sim::TriangleMesh plate_with_holes() {
  return test::beam_with_holes(0.2, 0.01, 0.06, {{-0.05, 0.01, 0.01}, {0.0, 0.004, 0.02}, {0.06, 0.015, 0.005}},
                               twin::Vec3::Zero());
}

// The deepest of points over the triangle at most `spacing` apart.
double sampled_depth(const sim::Solid& solid, const Triangle& t, double spacing) {
  const double longest = std::max({(t[1] - t[0]).norm(), (t[2] - t[1]).norm(), (t[0] - t[2]).norm()});
  const int n = std::max(1, static_cast<int>(std::ceil(longest / spacing)));
  double deepest = 0;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; i + j <= n; ++j) {
      const Eigen::Vector3d p = t[0] + (t[1] - t[0]) * (double(i) / n) + (t[2] - t[0]) * (double(j) / n);
      deepest = std::max(deepest, solid.depth(p, 0));
    }
  }
  return deepest;
}

}  // namespace

TEST_CASE("a sliver lying on a flat face with holes is given up whole, not cut to the resolution", "[mesh][solid]") {
  const auto solid = sim::solid_of(plate_with_holes());
  REQUIRE(solid->inside);
  const double tolerance = 1e-4, resolution = 5e-5;
  // 180 x 4 mm on the top, beside the holes (they reach z 0.02 at most).
  const Triangle beside{Eigen::Vector3d(-0.09, 0.01, 0.022), Eigen::Vector3d(0.09, 0.01, 0.022),
                        Eigen::Vector3d(0.09, 0.01, 0.026)};
  std::size_t asked = 0;
  CHECK_FALSE(sim::deepest_inside(*solid, beside, tolerance, resolution, false, &asked));
  CHECK(asked <= 4);  // 34 901 where only the nearest face bounds a piece
  CHECK(solid->flat_regions().regions() >= 2);  // top and bottom at least

  // Across the holes its shadow leaves the region; moved a little up, off the top, it meets no
  // face, which shows it clear as well.
  const Triangle across{Eigen::Vector3d(-0.09, 0.01, -0.002), Eigen::Vector3d(0.09, 0.01, -0.002),
                        Eigen::Vector3d(0.09, 0.01, 0.002)};
  asked = 0;
  CHECK_FALSE(sim::deepest_inside(*solid, across, tolerance, resolution, false, &asked));
  CHECK(asked <= 4);

  // 0.3 mm into the top: found, at that depth.
  Triangle pressed = beside;
  for (auto& p : pressed) p.y() -= 3e-4;
  const auto deep = sim::deepest_inside(*solid, pressed, tolerance, resolution, true);
  REQUIRE(deep);
  CHECK(deep->depth == Approx(3e-4).margin(resolution));
}

TEST_CASE("a sliver standing on a face, or along a bore's facet, is given up whole", "[mesh][solid]") {
  const double tolerance = 1e-4, resolution = 5e-5;
  const auto plate = sim::solid_of(plate_with_holes());
  // 180 mm long, standing on the top on its long edge, 20 mm high at one end.
  const Triangle standing{Eigen::Vector3d(-0.09, 0.01, 0.024), Eigen::Vector3d(0.09, 0.01, 0.024),
                          Eigen::Vector3d(0.09, 0.03, 0.024)};
  std::size_t asked = 0;
  CHECK_FALSE(sim::deepest_inside(*plate, standing, tolerance, resolution, false, &asked));
  CHECK(asked <= 4);  // 24 989 where a piece's nearest face and its middle alone bound it
  // Leaning 0.3 mm into the top at one end: found.
  const Triangle leaning{Eigen::Vector3d(-0.09, 0.0097, 0.024), Eigen::Vector3d(0.09, 0.01, 0.024),
                         Eigen::Vector3d(0.09, 0.03, 0.024)};
  const auto deep = sim::deepest_inside(*plate, leaning, tolerance, resolution, true);
  REQUIRE(deep);
  CHECK(deep->depth == Approx(3e-4).margin(resolution));

  // A pin's facet lying on a ring's bore facet, as two parts of the same size meshed alike.
  const int segments = 24;
  const double bore = 0.004;
  const auto ring = sim::solid_of(test::tube_mesh(segments, 0.01, bore, 0.02));
  const Eigen::Vector3d a(bore, -0.01, 0), b(bore * std::cos(2 * M_PI / segments), -0.01, bore * std::sin(2 * M_PI / segments));
  const Triangle facet{a, b, Eigen::Vector3d(b.x(), 0.03, b.z())};
  asked = 0;
  CHECK_FALSE(sim::deepest_inside(*ring, facet, tolerance, resolution, false, &asked));
  CHECK(asked <= 8);
}

TEST_CASE("a piece lying on a low step is found deep where it reaches into the step up", "[mesh][solid]") {
  const double a = 0.02;
  const auto solid = sim::solid_of(l_block(a, 0.03));
  REQUIRE(solid->inside);
  // On the low step's top (y = a), from its far end into the tall block to 5 mm from its far
  // wall: deepest 10 mm in, halfway between that wall and the step's.
  const Triangle reaching{Eigen::Vector3d(0.035, a, 0.014), Eigen::Vector3d(0.005, a, 0.015),
                          Eigen::Vector3d(0.035, a, 0.016)};
  const auto deep = sim::deepest_inside(*solid, reaching, 1e-4, 5e-5, true);
  REQUIRE(deep);
  CHECK(deep->depth == Approx(0.01).margin(1e-4));
  CHECK(deep->point.x() == Approx(0.01).margin(1e-4));
  // Short of the step: nothing.
  const Triangle short_of{Eigen::Vector3d(0.035, a, 0.014), Eigen::Vector3d(0.0201, a, 0.015),
                          Eigen::Vector3d(0.035, a, 0.016)};
  CHECK_FALSE(sim::deepest_inside(*solid, short_of, 1e-4, 5e-5));
}

TEST_CASE("deepest_inside misses no point that sampling finds deep, on flat faces with holes and steps",
          "[mesh][solid][property]") {
  const double tolerance = 1e-4, resolution = 5e-4, spacing = 2.5e-4;
  const int kPerSolid = test::kUnderSanitizers ? 30 : 150;  // the sampled depths are the cost
  std::vector<std::pair<std::string, std::unique_ptr<sim::Solid>>> solids;
  solids.emplace_back("plate with holes", sim::solid_of(plate_with_holes()));
  solids.emplace_back("ring", sim::solid_of(test::tube_mesh(48, 0.02, 0.012, 0.01)));
  solids.emplace_back("L step", sim::solid_of(l_block(0.02, 0.03)));
  solids.emplace_back("box", sim::solid_of(test::box_mesh({0.02, 0.01, 0.015})));
  std::mt19937 random(31);
  std::uniform_real_distribution<double> unit(0, 1);
  int found = 0, near_planes = 0;
  for (const auto& [name, solid] : solids) {
    REQUIRE(solid->inside);
    const auto& mesh = solid->mesh;
    std::vector<sim::Solid::Mesh::Face_index> faces(mesh.faces().begin(), mesh.faces().end());
    for (int k = 0; k < kPerSolid; ++k) {
      // Most lie in the plane of a face of the solid, just above or below it, some of them
      // long slivers; the rest anywhere near it.
      const auto f = faces[static_cast<std::size_t>(unit(random) * faces.size()) % faces.size()];
      const auto h = mesh.halfedge(f);
      const auto corner = [&](sim::Solid::Mesh::Vertex_index v) {
        const auto& p = mesh.point(v);
        return Eigen::Vector3d(p.x(), p.y(), p.z());
      };
      const Eigen::Vector3d p0 = corner(mesh.source(h)), p1 = corner(mesh.target(h)), p2 = corner(mesh.target(mesh.next(h)));
      const Eigen::Vector3d normal = (p1 - p0).cross(p2 - p0).normalized() * solid->orientation;
      const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
      double s = unit(random), r = unit(random);
      if (s + r > 1) s = 1 - s, r = 1 - r;
      const Eigen::Vector3d on = p0 + s * (p1 - p0) + r * (p2 - p0);
      Triangle t;
      if (k % 4 == 2) {
        // Standing on the face on one edge, leaning in or out, some just into it.
        const double turn = unit(random) * 2 * M_PI, length = 0.005 + unit(random) * 0.04;
        const Eigen::Vector3d along = std::cos(turn) * u + std::sin(turn) * v;
        const Eigen::Vector3d sink = -normal * unit(random) * 3 * tolerance * (k % 8 == 2);
        const Eigen::Vector3d base = on - along * length * unit(random) + sink;
        const Eigen::Vector3d lean = normal.cross(along) * (unit(random) - 0.5) * 0.02;
        t = {base, base + along * length, base + along * length * unit(random) + normal * (0.002 + unit(random) * 0.02) + lean};
      } else if (k % 4 != 3) {
        ++near_planes;
        const double offset = (unit(random) * 4 - 3) * tolerance;  // 0.3 mm in to 0.1 mm out
        const double length = 0.002 + unit(random) * 0.04, width = k % 2 ? 0.001 + unit(random) * 0.003 : length;
        const double turn = unit(random) * 2 * M_PI;
        const Eigen::Vector3d along = std::cos(turn) * u + std::sin(turn) * v, across = normal.cross(along);
        const Eigen::Vector3d base = on + offset * normal - along * length * unit(random);
        t = {base, base + along * length, base + along * length * unit(random) + across * width};
      } else {
        for (auto& c : t) c = on + Eigen::Vector3d(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5) * 0.03;
      }
      INFO(name << ", triangle " << k);
      const double sampled = sampled_depth(*solid, t, spacing);
      const auto deep = sim::deepest_inside(*solid, t, tolerance, resolution, true);
      if (sampled > tolerance + resolution) CHECK(deep);
      if (!deep) continue;
      ++found;
      CHECK(deep->depth > tolerance);
      CHECK(solid->depth(deep->point, 0) == Approx(deep->depth).margin(1e-9));  // a real point, as deep as said
      CHECK(deep->depth >= sampled - resolution);                               // the deepest, to within the resolution
    }
  }
  CHECK(found > kPerSolid * 4 / 6);  // the test asks deep triangles, not only clear ones
  CHECK(near_planes > kPerSolid * 4 * 2 / 5);
}
