#include "twin/planning/subassembly_planner.hpp"

#include <algorithm>
#include <cctype>
#include <map>
#include <optional>

#include "twin/model/source_ref.hpp"

namespace twin {
namespace {

constexpr double kAsideGap = 0.05;  // m between the product and a subassembly built beside it

Product empty_like(const Product& product, const std::string& name) {
  Product out(name, product.source());
  for (const auto& [type, part_type] : product.types()) {
    for (const auto& [interface, frame] : part_type.interfaces) out.set_type_interface(type, interface, frame);
    for (const auto& [interface, joint] : part_type.joints) out.set_type_joint(type, interface, joint);
  }
  return out;
}

DigitalPart alone(DigitalPart part) {
  part.subassembly.clear();
  return part;
}

// The subassembly as a product of its own, built beside the product on the station.
LoadedProduct subassembly_product(const LoadedProduct& product, const Subassembly& s, const Vec3& aside) {
  LoadedProduct out{empty_like(product.product, product.product.name() + "/" + s.name), {}, {}};
  std::map<PartIndex, PartIndex> index;
  for (PartIndex m : s.members) {
    DigitalPart part = alone(product.product.parts()[m]);
    part.final_pose.pretranslate(aside);
    index[m] = out.product.add_part(std::move(part));
    out.meshes.push_back(product.meshes[m]);
  }
  for (const Connection& c : product.product.connections()) {
    if (!index.count(c.part1) || !index.count(c.part2)) continue;
    const auto& parts = product.product.parts();
    out.product.connect(parts[c.part1].id, c.interface1, parts[c.part2].id, c.interface2, c.name, c.where);
  }
  // Its own parts' precedences hold while it is built.
  const auto& parts = product.product.parts();
  for (const auto& [before, after] : product.product.precedences()) {
    if (index.count(before) && index.count(after)) out.product.add_precedence(parts[before].id, parts[after].id, parts[after].where);
  }
  return out;
}

// The product with each subassembly one part (named after it, at its base's pose, of its
// members' merged mesh), linked to the rest where its members are. `origin`: what each part
// of the result stands for, in the product.
//
// A precedence that involves a subassembly's part holds for the whole subassembly (it goes in
// with its parts); one that cannot hold so (a part both before and after the same
// subassembly) is said in `conflicts`.
LoadedProduct product_of_units(const LoadedProduct& product, const std::vector<Subassembly>& subassemblies,
                               std::vector<const Subassembly*>& unit_of, std::vector<PartIndex>& origin,
                               std::vector<std::string>& conflicts) {
  const auto& parts = product.product.parts();
  LoadedProduct out{empty_like(product.product, product.product.name()), {}, {}};
  std::map<PartIndex, const Subassembly*> member_of;
  for (const auto& s : subassemblies) {
    for (PartIndex m : s.members) member_of[m] = &s;
  }
  std::map<const Subassembly*, std::string> id_of_unit;
  for (PartIndex p = 0; p < parts.size(); ++p) {
    const auto it = member_of.find(p);
    if (it == member_of.end()) {
      out.product.add_part(alone(parts[p]));
      out.meshes.push_back(product.meshes[p]);
      out.held_by.push_back(nullptr);
      unit_of.push_back(nullptr);
      origin.push_back(p);
      continue;
    }
    const Subassembly& s = *it->second;
    if (p != s.members.front()) continue;
    DigitalPart unit;
    unit.id = unit_id(parts[p].id);
    unit.name = s.name;
    unit.final_pose = parts[p].final_pose;
    unit.where = parts[p].where;
    // Its members' interfaces that link it to the rest, as "member/interface".
    for (const Connection& c : product.product.connections()) {
      for (const auto& [end, interface] : {std::pair{c.part1, c.interface1}, std::pair{c.part2, c.interface2}}) {
        if (member_of.count(end) && member_of[end] == &s) {
          unit.own_interfaces[parts[end].name + "/" + interface] = *product.product.interface_of(end, interface);
          if (const Joint* joint = product.product.joint_of(end, interface)) unit.own_joints[parts[end].name + "/" + interface] = *joint;
        }
      }
    }
    id_of_unit[&s] = unit.id;
    out.product.add_part(std::move(unit));
    out.meshes.push_back(merged_mesh(product, s.members));
    out.held_by.push_back(product.meshes[p]);  // gripped by its base, whose frame is the unit's
    unit_of.push_back(&s);
    origin.push_back(p);
  }
  const auto end_of = [&](PartIndex p, const std::string& interface) -> std::pair<std::string, std::string> {
    const auto it = member_of.find(p);
    if (it == member_of.end()) return {parts[p].id, interface};
    return {id_of_unit.at(it->second), parts[p].name + "/" + interface};
  };
  for (const Connection& c : product.product.connections()) {
    if (member_of.count(c.part1) && member_of.count(c.part2) && member_of[c.part1] == member_of[c.part2]) continue;
    const auto [a, ia] = end_of(c.part1, c.interface1);
    const auto [b, ib] = end_of(c.part2, c.interface2);
    out.product.connect(a, ia, b, ib, c.name, c.where);
  }
  for (const auto& [before, after] : product.product.precedences()) {
    const std::string first = end_of(before, "").first, then = end_of(after, "").first;
    if (first == then) continue;  // within one subassembly: it holds while that is built
    try {
      out.product.add_precedence(first, then, parts[after].where);
    } catch (const DescriptionError& e) {
      conflicts.push_back(e.what());
    }
  }
  return out;
}

std::vector<PartIndex> mapped(const std::vector<PartIndex>& parts, const std::vector<PartIndex>& to) {
  std::vector<PartIndex> out;
  for (PartIndex p : parts) out.push_back(to[p]);
  return out;
}

// A finding that names a step ("step 3: ...") names it by its number in the whole plan.
std::string renumbered(const std::string& message, std::size_t offset) {
  std::size_t digits = 0;
  if (message.rfind("step ", 0) != 0 || offset == 0) return message;
  while (5 + digits < message.size() && std::isdigit(static_cast<unsigned char>(message[5 + digits]))) ++digits;
  if (digits == 0) return message;
  return "step " + std::to_string(std::stoul(message.substr(5, digits)) + offset) + message.substr(5 + digits);
}

// `from`'s steps are in `into` already, the last ones.
void add_plan(Plan& into, Plan from, const std::string& prefix) {
  into.complete = into.complete && from.complete;
  into.backtracks += from.backtracks;
  into.trajectories_simulated += from.trajectories_simulated;
  for (auto& f : from.findings) {
    f.message = prefix + renumbered(f.message, into.steps.size() - from.steps.size());
    into.findings.push_back(std::move(f));
  }
}

}  // namespace

Eigen::AlignedBox3d final_bounds(const LoadedProduct& product, const std::vector<PartIndex>& parts) {
  Eigen::AlignedBox3d box;
  for (PartIndex p : parts) {
    const Pose& pose = product.product.parts()[p].final_pose;
    if (const auto& mesh = product.meshes[p]) {
      for (const auto& v : mesh->vertices) box.extend(pose * v);
    } else {
      box.extend(pose.translation());
    }
  }
  return box;
}


std::vector<Subassembly> subassemblies_of(const Product& product) {
  std::vector<Subassembly> out;
  std::map<std::string, std::size_t> by_name;
  for (PartIndex p = 0; p < product.parts().size(); ++p) {
    const std::string& name = product.parts()[p].subassembly;
    if (name.empty()) continue;
    const auto [it, fresh] = by_name.emplace(name, out.size());
    if (fresh) out.push_back({name, {}});
    out[it->second].members.push_back(p);
  }
  return out;
}

std::shared_ptr<const sim::TriangleMesh> merged_mesh(const LoadedProduct& product, const std::vector<PartIndex>& members) {
  auto out = std::make_shared<sim::TriangleMesh>();
  const Pose base = product.product.parts()[members.front()].final_pose.inverse();
  for (PartIndex m : members) {
    const auto& mesh = product.meshes[m];
    if (!mesh) continue;
    const Pose to_base = base * product.product.parts()[m].final_pose;
    const auto first = static_cast<std::uint32_t>(out->vertices.size());
    for (const auto& v : mesh->vertices) {
      out->vertices.push_back(to_base * v);
      out->bounds.extend(out->vertices.back());
    }
    for (const auto& t : mesh->triangles) out->triangles.push_back({t[0] + first, t[1] + first, t[2] + first});
    if (sim::pieces_are_exact(*mesh)) {
      for (const auto& piece : mesh->pieces) {
        out->pieces.emplace_back();
        for (auto v : piece) out->pieces.back().push_back(v + first);
      }
    } else {
      for (const auto& t : mesh->triangles) out->pieces.push_back({t[0] + first, t[1] + first, t[2] + first});
    }
  }
  if (out->pieces.size() == 1) out->convex = sim::is_convex(*out);
  out->hull_corners = sim::hull_corners(*out);
  return out;
}

PlanLevels plan_levels(const LoadedProduct& product) {
  PlanLevels out;
  out.subassemblies = subassemblies_of(product.product);
  // Each subassembly built beside what stands left of it, its lowest point on the station.
  std::vector<PartIndex> all(product.product.parts().size());
  for (PartIndex p = 0; p < all.size(); ++p) all[p] = p;
  double beside = final_bounds(product, all).max().x() + kAsideGap;
  for (const Subassembly& s : out.subassemblies) {
    const Eigen::AlignedBox3d box = final_bounds(product, s.members);
    const Vec3 aside(beside - box.min().x(), -box.min().y(), 0);
    beside += box.sizes().x() + kAsideGap;
    out.levels.push_back({s.name, subassembly_product(product, s, aside), s.members, {}, aside});
  }
  std::vector<const Subassembly*> unit_of;
  std::vector<PartIndex> origin;
  LoadedProduct units = product_of_units(product, out.subassemblies, unit_of, origin, out.conflicts);
  if (!out.conflicts.empty()) return out;
  std::vector<int> unit;
  for (const Subassembly* u : unit_of) unit.push_back(u ? static_cast<int>(u - out.subassemblies.data()) : -1);
  out.levels.push_back({"", std::move(units), std::move(origin), std::move(unit), Vec3::Zero()});
  return out;
}

namespace {

// Gravity at the product's level, where each subassembly is one part, asked of the product's
// own parts: a subassembly's members where it stands, fastened to each other where their
// joints fasten (made when it was built), and not one rigid body where they do not (a block
// on a plate stays a block on a plate). What would move is named by the level's parts.
class MembersGravity : public Gravity {
 public:
  MembersGravity(const LoadedProduct& product, const PlanLevel& level, const std::vector<Subassembly>& subassemblies,
                 const StabilityAnalysis& analysis)
      : product_(product), level_(level), analysis_(analysis) {
    level_part_of_.assign(product.product.parts().size(), 0);
    members_.resize(level.origin.size());
    for (PartIndex u = 0; u < level.origin.size(); ++u) {
      const int s = level.unit[u];
      members_[u] = s >= 0 ? subassemblies[static_cast<std::size_t>(s)].members : std::vector<PartIndex>{level.origin[u]};
      for (PartIndex m : members_[u]) level_part_of_[m] = u;
    }
    // The level's connections are the product's between parts of two of its parts, in order.
    int next = 0;
    for (const Connection& c : product.product.connections()) {
      level_connection_.push_back(level_part_of_[c.part1] == level_part_of_[c.part2] ? -1 : next++);
    }
  }

  std::optional<Instability> check(const std::vector<PlacedPart>& placed, const std::vector<PartIndex>& fixed,
                                   const std::vector<bool>& fastened, std::optional<PartIndex> added) const override {
    const auto& parts = product_.product.parts();
    std::vector<PlacedPart> members;
    for (const PlacedPart& u : placed) {
      const Pose moved = u.pose * parts[level_.origin[u.part]].final_pose.inverse();
      for (PartIndex m : members_[u.part]) members.push_back({m, moved * parts[m].final_pose});
    }
    std::vector<PartIndex> held;
    for (PartIndex u : fixed) held.insert(held.end(), members_[u].begin(), members_[u].end());
    const auto& connections = product_.product.connections();
    std::vector<bool> made(connections.size());
    for (std::size_t c = 0; c < connections.size(); ++c) {
      const int k = level_connection_[c];
      made[c] = k < 0 ? connections[c].joint.fastens() : static_cast<std::size_t>(k) < fastened.size() && fastened[k];
    }
    // A new part of one member is asked first on its own; a subassembly's members, together.
    std::optional<PartIndex> new_part;
    if (added && members_[*added].size() == 1) new_part = members_[*added].front();
    auto falls = analysis_.check(members, held, made, new_part);
    if (!falls) return falls;
    std::vector<PartIndex> group;
    for (PartIndex m : falls->parts) {
      if (std::find(group.begin(), group.end(), level_part_of_[m]) == group.end()) group.push_back(level_part_of_[m]);
    }
    falls->parts = std::move(group);
    return falls;
  }

  // The product's parts a part of the level stands for: a subassembly's members, or itself.
  const std::vector<PartIndex>& members(PartIndex level_part) const { return members_[level_part]; }

 private:
  const LoadedProduct& product_;
  const PlanLevel& level_;
  const StabilityAnalysis& analysis_;
  std::vector<std::vector<PartIndex>> members_;  // per part of the level
  std::vector<PartIndex> level_part_of_;         // per part of the product
  std::vector<int> level_connection_;            // per connection of the product; -1: inside a subassembly
};

}  // namespace

Plan plan_with_subassemblies(const LoadedProduct& product, SequencePlanner& sequence, PathPlanner& path,
                             const PlannerOptions& options, const StabilityAnalysis& stability) {
  const PlanLevels levels = plan_levels(product);
  Plan plan;
  plan.complete = true;
  plan.sequence_planner = sequence.name();
  plan.path_planner = path.name();
  plan.margin_threshold = options.margin_threshold;
  plan.margin_reach = options.margin_reach;
  // The whole plan is replayed once its levels are joined (plan_assembly), not level by level.
  PlannerOptions each = options;
  each.verify = false;
  for (const PlanLevel& level : levels.levels) {
    std::optional<MembersGravity> members;
    if (level.subassembly.empty()) members.emplace(product, level, levels.subassemblies, stability);
    each.gravity = members ? &*members : nullptr;
    Plan own = plan_assembly(level.product, sequence, path, each);
    for (PlanStep step : own.steps) {
      step.allowed = mapped(step.allowed, level.origin);
      if (members) {  // a fixture that holds a subassembly holds its members, as its gravity asked
        std::vector<PartIndex> held;
        for (PartIndex u : step.fixture) held.insert(held.end(), members->members(u).begin(), members->members(u).end());
        step.fixture = std::move(held);
      } else {
        step.fixture = mapped(step.fixture, level.origin);
      }
      if (!level.subassembly.empty()) {
        step.subassembly = level.subassembly;
      } else if (const int u = level.unit[step.part]; u >= 0) {
        const Subassembly& s = levels.subassemblies[static_cast<std::size_t>(u)];
        step.subassembly = s.name;
        step.carried.assign(s.members.begin() + 1, s.members.end());
      }
      step.part = level.origin[step.part];
      plan.steps.push_back(std::move(step));
    }
    add_plan(plan, std::move(own), level.subassembly.empty() ? "" : "subassembly " + level.subassembly + ": ");
    if (!level.subassembly.empty()) {
      plan.subassemblies.push_back({level.subassembly, level.origin, level.aside});
    }
  }
  if (!levels.conflicts.empty()) {
    plan.complete = false;
    for (const auto& why : levels.conflicts) {
      plan.findings.push_back({"infeasible", "the precedences cannot hold with each subassembly inserted whole: " + why, {}});
    }
  }
  return plan;
}

}  // namespace twin
