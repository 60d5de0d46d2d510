#pragma once
// The finished product checked against itself: every pair of parts that overlaps deeper
// than the contact tolerance at their final poses. Such an overlap is a slip in the
// description (a link offset, a mesh exported at the wrong place), and no plan can build
// it: the part that goes in second is "blocked by" the first whatever its path.
//
// Volumes, not surfaces: CGAL tells which points of one part's surface (its vertices and
// points over its triangles, at most 2 mm apart on small faces) lie inside the other part,
// and how far from its surface. Two faces that overlap flat, where no triangles cross, are
// found too. A part whose mesh is not closed has no inside; it is named, and only the
// other side of its pairs is checked. Where one of a pair is convex, Bullet's volumetric
// test of its hull decides first, which is much cheaper (a peg in its hole).

#include <string>
#include <vector>

#include "sim/collision/collision_world.hpp"
#include "twin/geometry/product_loader.hpp"

namespace twin {

struct Interference {
  PartIndex part1 = 0, part2 = 0;  // part1 < part2
  double depth = 0;                // m, the deepest contact between them
  // The samples of either part's surface that lie inside the other deeper than the tolerance,
  // in the product's frame: where they overlap (threads.hpp reads a thread from them).
  std::vector<Vec3> inside;
};

struct InterferenceCheck {
  std::vector<Interference> overlaps;
  std::vector<PartIndex> not_closed;  // parts whose mesh has no inside
};

InterferenceCheck find_interferences(const LoadedProduct& product, const sim::CollisionOptions& options = {});

// "idler_spacer overlaps panel_bearing by 1.0 mm in the finished product; check its link offsets"
std::string describe(const Product& product, const Interference& interference);

}  // namespace twin
