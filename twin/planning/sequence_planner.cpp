#include "twin/planning/sequence_planner.hpp"

#include <algorithm>
#include <stdexcept>

namespace twin {
namespace {

void sort_lowest_first(const AssemblyScene& scene, std::vector<PartIndex>& parts) {
  std::stable_sort(parts.begin(), parts.end(), [&](PartIndex a, PartIndex b) {
    return scene.final_bounds(a).min().y() < scene.final_bounds(b).min().y() - 1e-9;
  });
}

}  // namespace

std::vector<PartIndex> PaperSequencePlanner::candidates(const AssemblyScene& scene) const {
  const auto& frontier = scene.frontier();
  for (PartIndex p : frontier) {
    if (scene.stands_on_surface(p)) return {p};
  }
  std::vector<PartIndex> linked(frontier.begin(), frontier.end());
  sort_lowest_first(scene, linked);
  if (linked.empty()) return {};
  return {linked.front()};
}

std::vector<PartIndex> SearchSequencePlanner::candidates(const AssemblyScene& scene) const {
  std::vector<PartIndex> allowed(scene.frontier().begin(), scene.frontier().end());
  sort_lowest_first(scene, allowed);
  return allowed;
}

std::vector<PartIndex> GivenSequencePlanner::candidates(const AssemblyScene& scene) const {
  const auto& product = scene.product().product;
  for (const std::string& id : order_) {
    const auto part = product.find_part(id);
    if (!part || scene.is_assembled(*part)) continue;  // another level's, or in already
    if (scene.frontier().count(*part)) return {*part};
    return {};  // not allowed yet: the stored order does not hold for this product
  }
  return {};
}

std::unique_ptr<SequencePlanner> make_sequence_planner(const std::string& name) {
  if (name == "paper") return std::make_unique<PaperSequencePlanner>();
  if (name == "search") return std::make_unique<SearchSequencePlanner>();
  throw std::invalid_argument("unknown sequence planner '" + name + "' (paper, search)");
}

}  // namespace twin
