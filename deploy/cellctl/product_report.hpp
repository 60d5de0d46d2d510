#pragma once
// The finished product as people and programs read it: a table and a JSON document.

#include <ostream>

#include <nlohmann/json.hpp>

#include "twin/geometry/product_loader.hpp"
#include "twin/model/product.hpp"
#include "twin/planning/interference.hpp"

namespace cellctl {

// Schema "agile-cell/product" version 1, documented in docs/cli.md. With the finished
// product's interference check: the parts that overlap, and those whose mesh is not closed.
// And what loading repaired or found wrong in each mesh (`meshes`).
nlohmann::json product_json(const twin::LoadedProduct& loaded, const twin::InterferenceCheck& check);
void print_product_table(const twin::LoadedProduct& loaded, const twin::InterferenceCheck& check, std::ostream& out);

// Extrinsic X, Y, Z angles in degrees (the orientation attribute's own convention).
twin::Vec3 xyz_degrees(const twin::Quat& q);

}  // namespace cellctl
