#pragma once
// Meshes made in the tests: boxes, and a frame of one piece that is concave.

#include <array>
#include <vector>

#include "sim/mesh/triangle_mesh.hpp"

namespace test {

// Adds a closed box (12 triangles, outward) to the mesh's last piece.
inline void add_box(sim::TriangleMesh& mesh, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  if (mesh.pieces.empty()) mesh.pieces.emplace_back();
  const auto first = static_cast<std::uint32_t>(mesh.vertices.size());
  for (std::uint32_t i = 0; i < 8; ++i) {
    mesh.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
    mesh.pieces.back().push_back(first + i);
    mesh.bounds.extend(mesh.vertices.back());
  }
  for (const auto& f : std::vector<std::array<std::uint32_t, 4>>{
           {0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}}) {
    mesh.triangles.push_back({first + f[0], first + f[1], first + f[2]});
    mesh.triangles.push_back({first + f[0], first + f[2], first + f[3]});
  }
}

inline sim::TriangleMesh box_mesh(const Eigen::Vector3d& half) {
  sim::TriangleMesh mesh;
  add_box(mesh, -half, half);
  mesh.convex = sim::is_convex(mesh);
  return mesh;
}

// A square frame of one piece (a single mesh object, concave): four bars around a square
// hole of 2 * `hole` on a side, `thickness` high along y. Its hull fills the hole.
inline sim::TriangleMesh one_piece_frame(double hole, double bar, double thickness) {
  sim::TriangleMesh mesh;
  const double out = hole + bar, h = thickness / 2;
  add_box(mesh, {-out, -h, -out}, {-hole, h, out});    // left
  add_box(mesh, {hole, -h, -out}, {out, h, out});      // right
  add_box(mesh, {-hole, -h, -out}, {hole, h, -hole});  // front
  add_box(mesh, {-hole, -h, hole}, {hole, h, out});    // back
  return mesh;
}

}  // namespace test
