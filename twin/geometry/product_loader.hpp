#pragma once
// From a description file to the finished product: read, build, load meshes, place, set on
// the assembly surface. Everything checked; a DescriptionError leaves nothing behind.

#include <filesystem>
#include <memory>

#include "sim/mesh/triangle_mesh.hpp"
#include "twin/description/product_description.hpp"
#include "twin/geometry/placement.hpp"

namespace twin {

// Chooses the reader by file extension (.aml today).
std::unique_ptr<ProductDescription> open_description(const std::filesystem::path& file);

struct LoadedProduct {
  Product product;
  PartMeshes meshes;
  // What the gripper holds a part by, in the part's frame, where not its whole mesh: a
  // subassembly by its base, whose triangles come first in the part's mesh
  // (merged_mesh). Empty, or null for a part: its own mesh.
  PartMeshes held_by;
};

// Throws DescriptionError for the first part without a mesh: planning needs every part's shape.
void require_geometry(const LoadedProduct& product);

LoadedProduct load_product(const std::filesystem::path& file, sim::MeshCache& cache,
                           const PlacementOptions& options = {});

}  // namespace twin
