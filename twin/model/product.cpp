#include "twin/model/product.hpp"

namespace twin {

Product::Product(std::string name, std::filesystem::path source)
    : name_(std::move(name)), source_(std::move(source)) {}

void Product::set_type_interface(const std::string& type, const std::string& interface,
                                 const std::optional<Frame>& frame) {
  PartType& t = types_[type];
  t.name = type;
  t.interfaces[interface] = frame;
}

void Product::set_type_joint(const std::string& type, const std::string& interface, const Joint& joint) {
  PartType& t = types_[type];
  t.name = type;
  t.joints[interface] = joint;
}

const Joint* Product::joint_of(PartIndex part, const std::string& interface) const {
  const DigitalPart& p = parts_.at(part);
  if (const auto it = p.own_joints.find(interface); it != p.own_joints.end()) return &it->second;
  const auto type = types_.find(p.type);
  if (type == types_.end()) return nullptr;
  const auto it = type->second.joints.find(interface);
  return it == type->second.joints.end() ? nullptr : &it->second;
}

PartIndex Product::add_part(DigitalPart part) {
  if (auto existing = find_part(part.id)) {
    throw DescriptionError(part.where, "duplicate ID '" + part.id + "': part '" +
                                           parts_[*existing].name + "' (" +
                                           parts_[*existing].where.to_string() +
                                           ") has it already");
  }
  if (!part.type.empty()) types_[part.type].name = part.type;
  const PartIndex index = parts_.size();
  by_id_.emplace(part.id, index);
  parts_.push_back(std::move(part));
  by_part_.emplace_back();
  predecessors_.emplace_back();
  successors_.emplace_back();
  return index;
}

void Product::add_precedence(const std::string& before, const std::string& after, const SourceRef& where) {
  const auto resolve = [&](const std::string& id) {
    const auto index = find_part(id);
    if (!index) throw DescriptionError(where, "precedence names unknown part ID '" + id + "'");
    return *index;
  };
  const PartIndex first = resolve(before), then = resolve(after);
  if (first == then) throw DescriptionError(where, "precedence puts part '" + parts_[first].name + "' before itself");
  // A cycle: `then` already comes, directly or not, before `first`.
  std::vector<PartIndex> open{first};
  std::vector<bool> seen(parts_.size(), false);
  while (!open.empty()) {
    const PartIndex p = open.back();
    open.pop_back();
    if (p == then) {
      throw DescriptionError(where, "precedence '" + parts_[first].name + "' before '" + parts_[then].name +
                                        "' closes a cycle: the others put '" + parts_[then].name + "' first");
    }
    for (PartIndex q : predecessors_[p]) {
      if (!seen[q]) open.push_back(q), seen[q] = true;
    }
  }
  precedences_.emplace_back(first, then);
  predecessors_[then].push_back(first);
  successors_[first].push_back(then);
}

void Product::connect(const std::string& part_a, const std::string& interface_a,
                      const std::string& part_b, const std::string& interface_b,
                      const std::string& name, const SourceRef& where) {
  auto resolve = [&](const std::string& id, const std::string& interface) {
    const auto index = find_part(id);
    if (!index) throw DescriptionError(where, "link to unknown part ID '" + id + "'");
    const auto* frame = interface_of(*index, interface);
    const std::string& part_name = parts_[*index].name;
    if (!frame) {
      throw DescriptionError(where, "part '" + part_name + "' has no interface '" + interface + "'");
    }
    if (!frame->has_value()) {
      throw DescriptionError(where, "interface '" + interface + "' of part '" + part_name +
                                        "' has no coordinates (neither an Attribute of that "
                                        "name with x,y,z nor a Frame)");
    }
    return *index;
  };
  Connection c{resolve(part_a, interface_a), interface_a, resolve(part_b, interface_b),
               interface_b, name, where, {}};
  if (c.part1 == c.part2) {
    throw DescriptionError(where, "link joins part '" + parts_[c.part1].name + "' to itself");
  }
  // The joint: what either side declares; two that differ are a contradiction.
  const Joint* a = joint_of(c.part1, interface_a);
  const Joint* b = joint_of(c.part2, interface_b);
  if (a && b && (a->kind != b->kind || a->pitch != b->pitch)) {
    throw DescriptionError(where, "link '" + name + "' joins interfaces that declare different joints: " +
                                      joint_name(a->kind) + " (" + a->where.to_string() + ") and " + joint_name(b->kind) +
                                      " (" + b->where.to_string() + ")");
  }
  if (a || b) c.joint = a ? *a : *b;
  by_part_[c.part1].push_back(connections_.size());
  by_part_[c.part2].push_back(connections_.size());
  connections_.push_back(std::move(c));
}

std::optional<PartIndex> Product::find_part(const std::string& id) const {
  const auto it = by_id_.find(id);
  if (it == by_id_.end()) return std::nullopt;
  return it->second;
}

std::optional<PartIndex> Product::find_part_by_name(const std::string& name) const {
  for (PartIndex i = 0; i < parts_.size(); ++i) {
    if (parts_[i].name == name) return i;
  }
  return std::nullopt;
}

const std::optional<Frame>* Product::interface_of(PartIndex part,
                                                  const std::string& interface) const {
  const DigitalPart& p = parts_.at(part);
  const std::optional<Frame>* own = nullptr;
  if (auto it = p.own_interfaces.find(interface); it != p.own_interfaces.end()) own = &it->second;
  if (own && own->has_value()) return own;
  // AML editors copy a class's interfaces into each instance without coordinates: the
  // instance declares the interface, its class says where it is.
  if (auto t = types_.find(p.type); t != types_.end()) {
    if (auto it = t->second.interfaces.find(interface); it != t->second.interfaces.end()) {
      if (it->second.has_value() || !own) return &it->second;
    }
  }
  return own;
}

std::string short_type_name(const std::string& type) {
  const auto slash = type.find_last_of('/');
  return slash == std::string::npos ? type : type.substr(slash + 1);
}

}  // namespace twin
