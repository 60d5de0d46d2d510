#pragma once
// Builds OBJ meshes as sets of convex pieces (one OBJ object each): boxes, prisms, plates
// with round and square through-holes. Millimetres in, metres out.

#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace products {

struct Hole {
  double x = 0, z = 0;       // centre on the plate, mm
  double half_size = 0;      // circle radius or half the square's side, mm
  bool square = false;
  double cell_half = 0;      // half-width of the square cell the hole is cut from, mm
};

class MeshBuilder {
 public:
  // A convex prism: the polygon (x, z) in mm, extruded from y0 to y1.
  void prism(const std::vector<Eigen::Vector2d>& polygon, double y0, double y1);
  void box(double x0, double x1, double y0, double y1, double z0, double z1);
  void cylinder(double radius, double y0, double y1, int segments = 32);
  // A rectangular plate x0..x1, z0..z1, y0..y1 with vertical through-holes. Hole cells
  // must lie inside the plate and not overlap.
  void plate_with_holes(double x0, double x1, double z0, double z1, double y0, double y1,
                        const std::vector<Hole>& holes);

  void write_obj(const std::string& path, const std::string& comment) const;

 private:
  struct Piece {
    std::vector<Eigen::Vector3d> vertices;
    std::vector<std::vector<int>> faces;
  };
  std::vector<Piece> pieces_;
};

// Points on a circle (or on a square, along the same rays) at angles 2*pi*k/segments.
// With segments a multiple of 8, a square's corners are among them.
std::vector<Eigen::Vector2d> ring(double cx, double cz, double half_size, bool square, int segments);

}  // namespace products
