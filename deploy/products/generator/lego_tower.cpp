// The paper's Lego tower (section 5.1): 2x2 and 2x4 bricks at true scale, stacked with
// offsets, one 2x4 rotated, a 2x4 overhanging the tower and a 2x2 hanging under the overhang.
// Bricks are modelled without studs (docs/products.md says why).

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "deploy/products/generator/caex_writer.hpp"
#include "deploy/products/generator/mesh_builder.hpp"
#include "deploy/products/generator/products.hpp"

namespace products {
namespace {

constexpr double kPitch = 8.0;     // stud pitch, mm
constexpr double kHeight = 9.6;    // brick height without studs, mm
constexpr double kPlay = 0.1;      // a brick is 0.2 mm shorter than its studs' span

struct Brick {
  std::string name;
  int studs_x, studs_z;  // in the brick's own frame (2x4: 4 along x)
  int x0, z0, layer;     // lowest stud cell it covers, in the tower's stud grid
  bool rotated;          // turned 90 degrees about Y
  std::string color;

  int span_x() const { return rotated ? studs_z : studs_x; }
  int span_z() const { return rotated ? studs_x : studs_z; }
};

// clang-format off
const std::vector<Brick> kBricks = {
    {"B1", 4, 2, 0, 0, 0, false, "red"},     {"B2", 4, 2, 0, 2, 0, false, "red"},
    {"B3", 4, 2, 0, 0, 1, true, "blue"},     {"B4", 4, 2, 2, 0, 1, true, "blue"},
    {"B5", 2, 2, 0, 0, 2, false, "yellow"},  {"B6", 2, 2, 2, 1, 2, false, "yellow"},
    {"B7", 2, 2, 0, 2, 2, false, "yellow"},
    {"B8", 4, 2, 0, 0, 3, true, "green"},    {"overhang", 4, 2, 2, 1, 3, false, "white"},
    {"hanging", 2, 2, 4, 1, 2, false, "pink"},
    {"B9", 2, 2, 1, 1, 4, false, "black"},
};
// clang-format on

std::string type_of(const Brick& b) { return "Brick" + std::to_string(b.studs_z) + "x" + std::to_string(b.studs_x); }

// Stud (i, j) of a brick type, in the brick's frame (origin at the centre of its bottom).
Eigen::Vector2d stud_local(int studs_x, int studs_z, int i, int j) {
  return {(i - (studs_x - 1) / 2.0) * kPitch, (j - (studs_z - 1) / 2.0) * kPitch};
}

// Which of a brick's studs sits over the tower's stud cell (cx, cz).
std::string stud_name(const Brick& b, int cx, int cz) {
  const double wx = (cx + 0.5 - b.x0 - b.span_x() / 2.0) * kPitch;  // relative to the brick centre
  const double wz = (cz + 0.5 - b.z0 - b.span_z() / 2.0) * kPitch;
  // Rotation +90 deg about Y maps local (x, z) to world (z, -x); invert it.
  const double lx = b.rotated ? -wz : wx;
  const double lz = b.rotated ? wx : wz;
  const int i = static_cast<int>(std::lround(lx / kPitch + (b.studs_x - 1) / 2.0));
  const int j = static_cast<int>(std::lround(lz / kPitch + (b.studs_z - 1) / 2.0));
  return std::to_string(i) + "_" + std::to_string(j);
}

bool covers(const Brick& b, int cx, int cz) {
  return cx >= b.x0 && cx < b.x0 + b.span_x() && cz >= b.z0 && cz < b.z0 + b.span_z();
}

}  // namespace

void write_lego_tower(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir / "meshes");
  CaexWriter aml("lego-tower.aml", "LegoTower");
  aml.interface_class("IStud");
  aml.interface_class("IAntiStud");

  pugi::xml_node brick = aml.unit_class("Brick");
  for (auto [sx, sz] : {std::pair{2, 2}, std::pair{4, 2}}) {
    const std::string name = "Brick" + std::to_string(sz) + "x" + std::to_string(sx);
    const std::string mesh = "meshes/brick_" + std::to_string(sz) + "x" + std::to_string(sx) + ".obj";
    MeshBuilder m;
    m.box(-sx * kPitch / 2 + kPlay, sx * kPitch / 2 - kPlay, 0, kHeight, -sz * kPitch / 2 + kPlay,
          sz * kPitch / 2 - kPlay);
    m.write_obj((dir / mesh).string(), "Lego brick " + std::to_string(sz) + "x" + std::to_string(sx) + " without studs");

    pugi::xml_node c = aml.unit_class(name, "Brick");
    aml.geometry(c, mesh);
    for (int i = 0; i < sx; ++i) {
      for (int j = 0; j < sz; ++j) {
        const Eigen::Vector2d p = stud_local(sx, sz, i, j);
        const std::string stud = std::to_string(i) + "_" + std::to_string(j);
        // Studs clutch: a brick pressed onto another holds to it (the meshes have no studs).
        aml.interface_point(c, "top_" + stud, "IStud", Eigen::Vector3d(p.x(), kHeight, p.y()), "studs");
        aml.interface_point(c, "bottom_" + stud, "IAntiStud", Eigen::Vector3d(p.x(), 0, p.y()), "studs");
      }
    }
  }
  (void)brick;

  std::vector<pugi::xml_node> parts;
  for (const auto& b : kBricks) parts.push_back(aml.part(b.name, type_of(b), b.color, b.rotated ? "0,90,0" : "0,0,0"));

  // One link for every pair of bricks in touching layers that overlap, at their first
  // shared stud: the upper brick's bottom onto the lower brick's top.
  for (std::size_t u = 0; u < kBricks.size(); ++u) {
    for (std::size_t d = 0; d < kBricks.size(); ++d) {
      const Brick& upper = kBricks[u];
      const Brick& lower = kBricks[d];
      if (upper.layer != lower.layer + 1) continue;
      bool linked = false;
      for (int cx = upper.x0; cx < upper.x0 + upper.span_x() && !linked; ++cx) {
        for (int cz = upper.z0; cz < upper.z0 + upper.span_z() && !linked; ++cz) {
          if (!covers(lower, cx, cz)) continue;
          aml.link(upper.name + "-on-" + lower.name, parts[u], "bottom_" + stud_name(upper, cx, cz), parts[d],
                   "top_" + stud_name(lower, cx, cz));
          linked = true;
        }
      }
    }
  }
  aml.save((dir / "lego-tower.aml").string());
}

}  // namespace products
