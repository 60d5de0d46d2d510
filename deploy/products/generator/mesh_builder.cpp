#include "deploy/products/generator/mesh_builder.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <stdexcept>

namespace products {

std::vector<Eigen::Vector2d> ring(double cx, double cz, double half_size, bool square, int segments) {
  std::vector<Eigen::Vector2d> points;
  for (int k = 0; k < segments; ++k) {
    const double a = 2 * M_PI * k / segments;
    const double c = std::cos(a), s = std::sin(a);
    const double r = square ? half_size / std::max(std::abs(c), std::abs(s)) : half_size;
    points.emplace_back(cx + r * c, cz + r * s);
  }
  return points;
}

void MeshBuilder::prism(const std::vector<Eigen::Vector2d>& polygon, double y0, double y1) {
  Piece piece;
  const int n = static_cast<int>(polygon.size());
  for (const auto& p : polygon) piece.vertices.emplace_back(p.x(), y0, p.y());
  for (const auto& p : polygon) piece.vertices.emplace_back(p.x(), y1, p.y());
  std::vector<int> bottom, top;
  for (int i = 0; i < n; ++i) {
    bottom.push_back(i);
    top.push_back(n + i);
    piece.faces.push_back({i, (i + 1) % n, n + (i + 1) % n, n + i});
  }
  piece.faces.push_back(bottom);
  piece.faces.push_back(top);

  // Orient every face outwards: the piece is convex, so its centroid is inside.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& v : piece.vertices) centre += v;
  centre /= static_cast<double>(piece.vertices.size());
  for (auto& face : piece.faces) {
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    Eigen::Vector3d face_centre = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < face.size(); ++i) {
      const auto& a = piece.vertices[face[i]];
      const auto& b = piece.vertices[face[(i + 1) % face.size()]];
      normal += a.cross(b);  // Newell's method
      face_centre += a;
    }
    face_centre /= static_cast<double>(face.size());
    if (normal.dot(face_centre - centre) < 0) std::reverse(face.begin(), face.end());
  }
  pieces_.push_back(std::move(piece));
}

void MeshBuilder::box(double x0, double x1, double y0, double y1, double z0, double z1) {
  prism({{x0, z0}, {x1, z0}, {x1, z1}, {x0, z1}}, y0, y1);
}

void MeshBuilder::cylinder(double radius, double y0, double y1, int segments) {
  prism(ring(0, 0, radius, false, segments), y0, y1);
}

void MeshBuilder::plate_with_holes(double x0, double x1, double z0, double z1, double y0, double y1,
                                   const std::vector<Hole>& holes) {
  // Grid lines through the plate's edges and every hole cell's edges: each grid cell is
  // then either solid (one box) or inside exactly one hole cell.
  std::set<double> xs = {x0, x1}, zs = {z0, z1};
  for (const auto& h : holes) {
    if (h.cell_half <= h.half_size) throw std::invalid_argument("hole cell smaller than its hole");
    xs.insert({h.x - h.cell_half, h.x + h.cell_half});
    zs.insert({h.z - h.cell_half, h.z + h.cell_half});
  }
  const std::vector<double> gx(xs.begin(), xs.end()), gz(zs.begin(), zs.end());
  for (std::size_t i = 0; i + 1 < gx.size(); ++i) {
    for (std::size_t j = 0; j + 1 < gz.size(); ++j) {
      const double cx = (gx[i] + gx[i + 1]) / 2, cz = (gz[j] + gz[j + 1]) / 2;
      const bool in_hole_cell = std::any_of(holes.begin(), holes.end(), [&](const Hole& h) {
        return std::abs(cx - h.x) < h.cell_half && std::abs(cz - h.z) < h.cell_half;
      });
      if (!in_hole_cell) box(gx[i], gx[i + 1], y0, y1, gz[j], gz[j + 1]);
    }
  }
  // A hole cell is a ring of convex quads between the hole and the cell's square outline.
  constexpr int segments = 32;
  for (const auto& h : holes) {
    const auto inner = ring(h.x, h.z, h.half_size, h.square, segments);
    const auto outer = ring(h.x, h.z, h.cell_half, true, segments);
    for (int k = 0; k < segments; ++k) {
      const int n = (k + 1) % segments;
      prism({inner[k], inner[n], outer[n], outer[k]}, y0, y1);
    }
  }
}

void MeshBuilder::write_obj(const std::string& path, const std::string& comment) const {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << "# " << comment << "\n# Units: metres. Each object is one convex piece.\n";
  out.precision(7);
  int base = 1;
  for (std::size_t p = 0; p < pieces_.size(); ++p) {
    out << "o piece_" << p << '\n';
    for (const auto& v : pieces_[p].vertices) {
      out << "v " << v.x() / 1000 << ' ' << v.y() / 1000 << ' ' << v.z() / 1000 << '\n';
    }
    for (const auto& f : pieces_[p].faces) {
      out << 'f';
      for (int i : f) out << ' ' << base + i;
      out << '\n';
    }
    base += static_cast<int>(pieces_[p].vertices.size());
  }
}

}  // namespace products
