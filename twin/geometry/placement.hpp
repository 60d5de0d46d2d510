#pragma once
// The finished product's geometry (paper Fig. 4): where every part sits once assembled.

#include <memory>
#include <vector>

#include "sim/mesh/triangle_mesh.hpp"
#include "twin/model/product.hpp"

namespace twin {

struct PlacementOptions {
  // Links that close a loop may disagree by this much (metres) before it is an error.
  double loop_tolerance = 1e-4;
};

// Puts the first part at the origin with its orientation, then walks the links outwards:
// each newly reached part is turned to its orientation and moved so that its connection
// point coincides with its partner's. Sets DigitalPart::final_pose.
// Throws DescriptionError for a link whose loop disagrees and for parts no link reaches.
void place_parts(Product& product, const PlacementOptions& options = {});

// Each part's mesh, by part index; nullptr for a part without geometry.
using PartMeshes = std::vector<std::shared_ptr<const sim::TriangleMesh>>;

// Lifts or lowers the whole product so that its lowest point lies at height 0 (Y up).
// A part without a mesh counts as the point at its origin.
void set_on_surface(Product& product, const PartMeshes& meshes);

}  // namespace twin
