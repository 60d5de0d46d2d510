#pragma once
// Meshes made in the tests: boxes, a frame of one piece that is concave, and tubes.

#include <array>
#include <cmath>
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

// A tube along y of one piece, as a CAD export of a ring writes it: `segments` around, from
// radius `inner` to `outer` (m), `height` tall; `inner` 0: a solid pin. 8 triangles per
// segment (6 for a pin), facing outwards. Only its shape: nothing of what loading finds.
inline sim::TriangleMesh tube_mesh(int segments, double outer, double inner, double height) {
  sim::TriangleMesh m;
  m.pieces.emplace_back();
  const bool solid = inner <= 0;
  for (const double y : {0.0, height}) {
    for (int k = 0; k < segments; ++k) {
      const double t = 2 * M_PI * k / segments;
      m.vertices.emplace_back(outer * std::cos(t), y, outer * std::sin(t));
      m.vertices.emplace_back(solid ? 0 : inner * std::cos(t), y, solid ? 0 : inner * std::sin(t));
    }
  }
  const auto o = [&](int level, int k) { return static_cast<std::uint32_t>(level * 2 * segments + 2 * (k % segments)); };
  for (int k = 0; k < segments; ++k) {
    const auto a = o(0, k), b = o(0, k + 1), c = o(1, k + 1), d = o(1, k);
    m.triangles.insert(m.triangles.end(), {{a, c, b}, {a, d, c}});  // outside
    if (!solid) m.triangles.insert(m.triangles.end(), {{a + 1, b + 1, c + 1}, {a + 1, c + 1, d + 1}});  // bore
    m.triangles.insert(m.triangles.end(), {{d, c + 1, c}, {d, d + 1, c + 1}});  // top
    m.triangles.insert(m.triangles.end(), {{a, b, b + 1}, {a, b + 1, a + 1}});  // bottom
  }
  for (std::uint32_t i = 0; i < m.vertices.size(); ++i) {
    m.pieces.back().push_back(i);
    m.bounds.extend(m.vertices[i]);
  }
  return m;
}

// A tube along y from `y0` to `y1` of one piece whose outer and inner radii (m) are functions
// of the angle round y (t = atan2(z, x)) and the height: a thread is r = f(y + pitch t / 2 pi).
// `segments` around, `levels` up; an inner radius of 0 makes a solid rod. Faces outwards.
template <class Outer, class Inner>
sim::TriangleMesh revolved_tube(int segments, int levels, double y0, double y1, Outer outer, Inner inner) {
  sim::TriangleMesh m;
  m.pieces.emplace_back();
  for (int level = 0; level <= levels; ++level) {
    const double y = y0 + (y1 - y0) * level / levels;
    for (int k = 0; k < segments; ++k) {
      const double t = 2 * M_PI * k / segments;
      const double ro = outer(t, y), ri = inner(t, y);
      m.vertices.emplace_back(ro * std::cos(t), y, ro * std::sin(t));
      m.vertices.emplace_back(ri * std::cos(t), y, ri * std::sin(t));
    }
  }
  const auto o = [&](int level, int k) { return static_cast<std::uint32_t>(level * 2 * segments + 2 * (k % segments)); };
  const bool solid = inner(0.0, y0) <= 0;
  for (int level = 0; level < levels; ++level) {
    for (int k = 0; k < segments; ++k) {
      const auto a = o(level, k), b = o(level, k + 1), c = o(level + 1, k + 1), d = o(level + 1, k);
      m.triangles.insert(m.triangles.end(), {{a, c, b}, {a, d, c}});  // outside
      if (!solid) m.triangles.insert(m.triangles.end(), {{a + 1, b + 1, c + 1}, {a + 1, c + 1, d + 1}});  // bore
    }
  }
  for (int k = 0; k < segments; ++k) {
    const auto a = o(0, k), b = o(0, k + 1), c = o(levels, k + 1), d = o(levels, k);
    if (solid) {  // a fan round one middle vertex at each end: closed
      m.triangles.push_back({d, o(levels, 0) + 1, c});
      m.triangles.push_back({a, b, o(0, 0) + 1});
      continue;
    }
    m.triangles.insert(m.triangles.end(), {{d, c + 1, c}, {d, d + 1, c + 1}});  // top
    m.triangles.insert(m.triangles.end(), {{a, b, b + 1}, {a, b + 1, a + 1}});  // bottom
  }
  for (std::uint32_t i = 0; i < m.vertices.size(); ++i) {
    m.pieces.back().push_back(i);
    m.bounds.extend(m.vertices[i]);
  }
  return m;
}

// A U channel of one piece along x, as a CAD export writes it: its long faces two triangles
// each from end to end, so no corner and no middle of them lies near the channel's own
// middle. Open upwards: a base `thickness` thick, walls `thickness` thick and `height` tall,
// `width` across (z), `length` long (m), lying on y = 0.
inline sim::TriangleMesh u_channel(double length, double width, double height, double thickness) {
  sim::TriangleMesh m;
  m.pieces.emplace_back();
  const double w = width / 2, t = thickness;
  // The profile in (z, y) and its triangles.
  const std::vector<std::array<double, 2>> profile{{-w, 0}, {w, 0}, {w, height}, {w - t, height},
                                                   {w - t, t}, {-w + t, t}, {-w + t, height}, {-w, height}};
  const std::vector<std::array<std::uint32_t, 3>> cap{{0, 1, 4}, {0, 4, 5}, {1, 2, 3}, {1, 3, 4}, {0, 5, 6}, {0, 6, 7}};
  const auto n = static_cast<std::uint32_t>(profile.size());
  for (const double x : {-length / 2, length / 2}) {
    for (const auto& [z, y] : profile) m.vertices.emplace_back(x, y, z);
  }
  for (const auto& c : cap) {
    m.triangles.push_back({c[0], c[1], c[2]});              // at -x, facing -x
    m.triangles.push_back({c[0] + n, c[2] + n, c[1] + n});  // at +x, facing +x
  }
  for (std::uint32_t k = 0; k < n; ++k) {
    const std::uint32_t a = k, b = (k + 1) % n;
    m.triangles.push_back({a, b + n, b});
    m.triangles.push_back({a, a + n, b + n});
  }
  for (std::uint32_t i = 0; i < m.vertices.size(); ++i) {
    m.pieces.back().push_back(i);
    m.bounds.extend(m.vertices[i]);
  }
  return m;
}

}  // namespace test
