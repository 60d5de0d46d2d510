#include "twin/planning/sequence_planner.hpp"

#include <algorithm>
#include <stdexcept>

namespace twin {
namespace {

constexpr double kOnSurface = 1e-4;  // m

void sort_lowest_first(const AssemblyScene& scene, std::vector<PartIndex>& parts) {
  std::stable_sort(parts.begin(), parts.end(), [&](PartIndex a, PartIndex b) {
    return scene.final_bounds(a).min().y() < scene.final_bounds(b).min().y() - 1e-9;
  });
}

}  // namespace

bool stands_on_surface(const AssemblyScene& scene, PartIndex part) {
  return scene.final_bounds(part).min().y() < kOnSurface;
}

bool linked_to_assembled(const AssemblyScene& scene, PartIndex part) {
  const Product& product = scene.product().product;
  for (std::size_t ci : product.connections_of(part)) {
    const Connection& c = product.connections()[ci];
    if (scene.is_assembled(c.part1 == part ? c.part2 : c.part1)) return true;
  }
  return false;
}

std::vector<PartIndex> parts_the_links_allow(const AssemblyScene& scene) {
  std::vector<PartIndex> allowed;
  for (PartIndex p = 0; p < scene.product().product.parts().size(); ++p) {
    if (scene.is_assembled(p)) continue;
    if (stands_on_surface(scene, p) || linked_to_assembled(scene, p)) allowed.push_back(p);
  }
  return allowed;
}

std::vector<PartIndex> PaperSequencePlanner::candidates(const AssemblyScene& scene) const {
  const std::size_t count = scene.product().product.parts().size();
  for (PartIndex p = 0; p < count; ++p) {
    if (!scene.is_assembled(p) && stands_on_surface(scene, p)) return {p};
  }
  std::vector<PartIndex> linked;
  for (PartIndex p = 0; p < count; ++p) {
    if (!scene.is_assembled(p) && linked_to_assembled(scene, p)) linked.push_back(p);
  }
  sort_lowest_first(scene, linked);
  if (linked.empty()) return {};
  return {linked.front()};
}

std::vector<PartIndex> SearchSequencePlanner::candidates(const AssemblyScene& scene) const {
  std::vector<PartIndex> allowed = parts_the_links_allow(scene);
  sort_lowest_first(scene, allowed);
  return allowed;
}

std::unique_ptr<SequencePlanner> make_sequence_planner(const std::string& name) {
  if (name == "paper") return std::make_unique<PaperSequencePlanner>();
  if (name == "search") return std::make_unique<SearchSequencePlanner>();
  throw std::invalid_argument("unknown sequence planner '" + name + "' (paper, search)");
}

}  // namespace twin
