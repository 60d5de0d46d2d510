#pragma once
// Writes a product description again with ordering constraints added, as the AutomationML
// convention the reader honours (docs/automationml.md): an Attribute "AssemblyPrecedence" on
// the product's element (on the later part's own element where the parts stand at the top of
// the hierarchy), one child Attribute per rule with "Before" and "After" part IDs. The rest of
// the file is kept as it was.

#include <filesystem>
#include <utility>
#include <vector>

#include "twin/model/product.hpp"

namespace twin {

// `out` in another folder than the product's file gets the meshes it refers to copied beside
// it, at the same relative paths. Throws std::runtime_error if it cannot write.
void write_with_precedences(const Product& product, const std::vector<std::pair<PartIndex, PartIndex>>& precedences,
                            const std::filesystem::path& out);

}  // namespace twin
