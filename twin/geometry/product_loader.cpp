#include "twin/geometry/product_loader.hpp"

#include <algorithm>

#include "twin/description/automationml/automationml_description.hpp"

namespace twin {

std::unique_ptr<ProductDescription> open_description(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".aml" || ext == ".xml" || ext == ".caex") return std::make_unique<AutomationMLDescription>(file);
  throw DescriptionError({file.string(), 0, ""}, "unknown product description format '" + ext +
                                                     "' (expected an AutomationML .aml file)");
}

LoadedProduct load_product(const std::filesystem::path& file, sim::MeshCache& cache,
                           const PlacementOptions& options) {
  LoadedProduct loaded{build_product(*open_description(file)), {}, {}};
  for (const auto& part : loaded.product.parts()) {
    if (!part.mesh) {
      loaded.meshes.push_back(nullptr);
      continue;
    }
    try {
      loaded.meshes.push_back(cache.get(part.mesh->file, part.mesh->scale));
    } catch (const sim::MeshError& e) {
      throw DescriptionError(part.mesh->where, e.what());
    }
  }
  place_parts(loaded.product, options);
  set_on_surface(loaded.product, loaded.meshes);
  return loaded;
}

void require_geometry(const LoadedProduct& loaded) {
  for (std::size_t i = 0; i < loaded.meshes.size(); ++i) {
    if (!loaded.meshes[i]) {
      const auto& part = loaded.product.parts()[i];
      throw DescriptionError(part.where, "part '" + part.name + "' has no geometry to plan with");
    }
  }
}

}  // namespace twin
