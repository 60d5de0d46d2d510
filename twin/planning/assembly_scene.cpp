#include "twin/planning/assembly_scene.hpp"

#include <algorithm>

#include "twin/planning/finger_contact.hpp"

namespace twin {
namespace {

constexpr double kOnSurface = 1e-4;  // m: a part this close to y = 0 stands on the station
constexpr double kShortOfSeat = 1e-3;  // m: where insertion margins stop (AssemblyScene::margin)
// m: a finger holds where the part's surface is this near its pad (a gripper closes that much
// onto a part that is a little narrower there than its box).
constexpr double kFingerReach = 1e-3;

Pose translation(const Vec3& t) {
  Pose p = Pose::Identity();
  p.translation() = t;
  return p;
}

}  // namespace

AssemblyScene::AssemblyScene(const LoadedProduct& product, sim::CollisionOptions options, fb::GripperGeometry gripper)
    : product_(product), gripper_(gripper), world_(options) {
  const auto& parts = product.product.parts();
  const auto box_of = [&](PartIndex i, const std::shared_ptr<const sim::TriangleMesh>& mesh) {
    Eigen::AlignedBox3d box;
    if (mesh) {
      for (const auto& v : mesh->vertices) box.extend(parts[i].final_pose * v);
    } else {
      box.extend(parts[i].final_pose.translation());
    }
    return box;
  };
  for (PartIndex i = 0; i < parts.size(); ++i) {
    bounds_.push_back(box_of(i, product.meshes[i]));
    grasp_bounds_.push_back(box_of(i, held_by(i)));
  }
  for (PartIndex i = 0; i < parts.size(); ++i) update_frontier(i);
  // The station's surface: a slab whose top is the assembly surface, y = 0.
  const sim::BodyId station = world_.add_static_box("station", Vec3(1.0, 0.025, 1.0), translation(Vec3(0, -0.025, 0)));
  names_[station] = "station";
}

void AssemblyScene::assemble(PartIndex part) {
  if (is_assembled(part)) return;
  const auto& p = product_.product.parts()[part];
  const sim::BodyId id = world_.add_static_mesh(p.name, product_.meshes[part], p.final_pose);
  bodies_[part] = id;
  names_[id] = p.name;
  assembled_bounds_.extend(bounds_[part]);
  update_frontier(part);
  for (PartIndex neighbour : neighbours(part)) update_frontier(neighbour);
  for (PartIndex next : product_.product.successors(part)) update_frontier(next);
}

void AssemblyScene::disassemble(PartIndex part) {
  const auto it = bodies_.find(part);
  if (it == bodies_.end()) return;
  world_.remove(it->second);
  names_.erase(it->second);
  bodies_.erase(it);
  assembled_bounds_.setEmpty();
  for (const auto& [p, _] : bodies_) assembled_bounds_.extend(bounds_[p]);
  update_frontier(part);
  for (PartIndex neighbour : neighbours(part)) update_frontier(neighbour);
  for (PartIndex next : product_.product.successors(part)) update_frontier(next);
}

void AssemblyScene::link(PartIndex a, PartIndex b) {
  links_.emplace_back(a, b);
  update_frontier(a);
  update_frontier(b);
}

std::vector<PartIndex> AssemblyScene::neighbours(PartIndex part) const {
  std::vector<PartIndex> out;
  for (const auto& [a, b] : links_) {
    if (a == part || b == part) out.push_back(a == part ? b : a);
  }
  const Product& product = product_.product;
  for (std::size_t ci : product.connections_of(part)) {
    const Connection& c = product.connections()[ci];
    out.push_back(c.part1 == part ? c.part2 : c.part1);
  }
  return out;
}

bool AssemblyScene::stands_on_surface(PartIndex part) const { return bounds_[part].min().y() < kOnSurface; }

bool AssemblyScene::linked_to_assembled(PartIndex part) const {
  const auto n = neighbours(part);
  return std::any_of(n.begin(), n.end(), [&](PartIndex q) { return is_assembled(q); });
}

void AssemblyScene::update_frontier(PartIndex part) {
  const auto& before = product_.product.predecessors(part);
  const bool preceded = std::all_of(before.begin(), before.end(), [&](PartIndex p) { return is_assembled(p); });
  if (!is_assembled(part) && preceded && (stands_on_surface(part) || linked_to_assembled(part))) {
    frontier_.insert(part);
  } else {
    frontier_.erase(part);
  }
}

std::vector<Grasp> AssemblyScene::grasps(PartIndex part, const Vec3& direction) const {
  const Pose& final_pose = product_.product.parts()[part].final_pose;
  std::vector<Grasp> out = grasps_for(grasp_bounds_[part], final_pose, direction, gripper_);
  // Then, for a part that stands turned about the vertical, across its own faces.
  const Footprint& f = footprint(part);
  if (f.turned) {
    auto turned = turned_grasps_for(f.turned_box, f.yaw, final_pose, direction, gripper_);
    out.insert(out.end(), turned.begin(), turned.end());
  }
  return out;
}

const AssemblyScene::Footprint& AssemblyScene::footprint(PartIndex part) const {
  auto [it, made] = footprints_.try_emplace(part);
  Footprint& f = it->second;
  const auto& mesh = held_by(part);
  if (!made || !mesh) return f;
  std::vector<Vec3> points;
  points.reserve(mesh->vertices.size());
  for (const auto& v : mesh->vertices) points.push_back(product_.product.parts()[part].final_pose * v);
  f.yaw = footprint_yaw(points);
  // Within a degree of the axes the boxes are the same.
  f.turned = std::min(f.yaw, M_PI / 2 - f.yaw) > M_PI / 180;
  const Pose unturn = unturn_by(f.yaw);
  for (const Vec3& p : points) f.turned_box.extend(unturn * p);
  return f;
}

const HeldPart& AssemblyScene::hold(PartIndex part, const Grasp& grasp) const {
  auto [it, made] = held_.try_emplace({part, grasp.label, grasp.opening});
  HeldPart& held = it->second;
  if (!made) return held;
  const double margin = world_.options().shape_margin;
  if (const auto& mesh = product_.meshes[part]) held.with_arm.add_mesh("part", mesh, Pose::Identity(), margin);
  for (const auto& box : fb::gripper_boxes(gripper_, grasp.opening)) {
    const std::string member = box.name.rfind("finger", 0) == 0 ? "finger" : box.name;
    held.with_arm.add_box(member, box.half_extents, grasp.gripper * box.pose, margin);
    held.arm.add_box(member, box.half_extents, box.pose, margin);
  }
  return held;
}

std::optional<Collision> AssemblyScene::collision_at(const sim::MovingBody& body, const Pose& pose,
                                                     const std::string& phase) const {
  if (auto c = world_.penetration(body, pose)) return to_collision(*c, phase);
  return std::nullopt;
}

const std::shared_ptr<const sim::TriangleMesh>& AssemblyScene::held_by(PartIndex part) const {
  const auto& held = product_.held_by;
  return part < held.size() && held[part] ? held[part] : product_.meshes[part];
}

bool AssemblyScene::holds(PartIndex part, const Grasp& grasp) const {
  const auto& mesh = held_by(part);
  if (!mesh) return true;
  const auto key = std::make_pair(part, grasp.label);
  if (const auto known = holds_.find(key); known != holds_.end()) return known->second;
  bool ok = fingers_touch(*mesh, grasp, gripper_, kFingerReach);
  // Held by its base, a subassembly's other members (its mesh after the base's triangles)
  // go with the gripper: it must not stand in them.
  const auto& whole = product_.meshes[part];
  if (ok && whole && whole != mesh) {
    ok = gripper_clear_of(*whole, mesh->triangles.size(), grasp, gripper_, world_.options().contact_tolerance);
    if (!ok) in_members_[part].insert(grasp.label);
  }
  return holds_[key] = ok;
}

std::size_t AssemblyScene::grasps_in_members(PartIndex part) const {
  const auto it = in_members_.find(part);
  return it == in_members_.end() ? 0 : it->second.size();
}

std::optional<Collision> AssemblyScene::simulate(PartIndex part, const Trajectory& trajectory) const {
  const auto& w = trajectory.waypoints;
  if (w.empty()) return std::nullopt;
  if (!holds(part, trajectory.grasp)) return Collision{"", "finger", 0, "gripping"};
  const HeldPart& held = hold(part, trajectory.grasp);
  if (w.front().holding) {
    if (auto c = collision_at(held.with_arm, w.front().part, w.front().phase)) return c;
  }
  // Turning into its thread, the part goes into the mate by the thread's overlap: the part and
  // gripper are checked against all else, the gripper alone against the mate too.
  const sim::BodyId mate = thread_mate(trajectory);
  for (std::size_t i = 1; i < w.size(); ++i) {
    std::optional<sim::Contact> contact;
    if (!w[i].holding) {
      contact = world_.sweep(held.arm, w[i - 1].gripper, w[i].gripper);
    } else if (w[i].phase == "screw" && mate >= 0) {
      contact = world_.sweep(held.with_arm, w[i - 1].part, w[i].part, mate);
      if (!contact) contact = world_.sweep(held.arm, w[i - 1].gripper, w[i].gripper);
    } else {
      contact = world_.sweep(held.with_arm, w[i - 1].part, w[i].part);
    }
    if (contact) return to_collision(*contact, w[i].phase);
  }
  return std::nullopt;
}

sim::BodyId AssemblyScene::thread_mate(const Trajectory& trajectory) const {
  if (!trajectory.screw) return -1;
  const auto it = bodies_.find(trajectory.screw->mate);
  return it == bodies_.end() ? -1 : it->second;
}

std::optional<Collision> KnownCollisions::recurring(const AssemblyScene& scene, PartIndex part, const std::string& trajectory,
                                                    const std::string& grasp) const {
  const auto it = known_.find({part, trajectory, grasp});
  if (it == known_.end()) return std::nullopt;
  for (const Collision& c : it->second) {
    const auto other = scene.product().product.find_part_by_name(c.with);
    if (c.with == "station" || (other && scene.is_assembled(*other))) {
      ++answered_;
      return c;
    }
  }
  return std::nullopt;
}

void KnownCollisions::remember(PartIndex part, const std::string& trajectory, const std::string& grasp,
                               const Collision& collision) {
  if (collision.phase != "insert" && collision.phase != "release" && collision.phase != "retreat") return;
  known_[{part, trajectory, grasp}].push_back(collision);
}

std::optional<Collision> AssemblyScene::simulate_grasps(PartIndex part, Trajectory& trajectory, KnownCollisions* known) const {
  const std::vector<Grasp> all = grasps(part, trajectory.direction);
  if (all.empty()) {
    // Narrower than the gripper opens on no pair of faces: by how much, at the narrowest.
    return Collision{"", "gripper", grasp_bounds(part).sizes().minCoeff() - gripper_.max_opening, "grasp"};
  }
  // The grasps that hold the part, its own first; where none does, it keeps its own.
  std::vector<Grasp> holding;
  if (holds(part, trajectory.grasp)) holding.push_back(trajectory.grasp);
  for (const Grasp& g : all) {
    if (g.label != trajectory.grasp.label && holds(part, g)) holding.push_back(g);
  }
  const auto run = [&](const Grasp& grasp) {
    trajectory.hold_by(grasp);
    if (known) {
      if (auto c = known->recurring(*this, part, trajectory.label, grasp.label)) return c;
    }
    auto c = simulate(part, trajectory);
    if (known && c) known->remember(part, trajectory.label, grasp.label, *c);
    return c;
  };
  std::optional<Collision> first;
  if (!holding.empty()) {
    first = run(holding.front());
    if (!first || first->member == "part") return first;  // no other grasp helps a part that hits
    for (std::size_t i = 1; i < holding.size(); ++i) {
      if (!run(holding[i])) return std::nullopt;
    }
  }
  // Then beside the part's centre (off_centre_grasps), where the centred fingers met
  // something (a post by the part's middle; the station, under a side grasp moved up) or
  // closed on air: each side and closing axis once, the fingers half-way in.
  const Grasp own = trajectory.grasp;
  for (const Grasp& centred : all) {
    if (centred.reach != Grasp::Reach::half) continue;
    for (const Grasp& g : off_centre(part, centred)) {
      if (holds(part, g) && !run(g)) return std::nullopt;
    }
  }
  if (holding.empty()) {
    trajectory.hold_by(own);
    return Collision{"", "finger", 0, "gripping"};
  }
  trajectory.hold_by(holding.front());
  return first;
}

const std::vector<Grasp>& AssemblyScene::off_centre(PartIndex part, const Grasp& centred) const {
  auto [it, made] = off_centre_.try_emplace({part, centred.label});
  if (made) {
    if (const auto& mesh = held_by(part)) it->second = off_centre_grasps(centred, *mesh, gripper_);
  }
  return it->second;
}

std::optional<Margin> AssemblyScene::margin(PartIndex part, const Trajectory& trajectory, double reach) const {
  constexpr double kAlongInsertion = 0.7;  // cos 45°: a contact normal this near the direction is a seat's
  const Vec3 direction = trajectory.direction;
  const sim::ClearanceFilter counts = [&](const sim::Clearance& c) {
    return !(c.member == "part" && c.normal.dot(direction) < -kAlongInsertion);
  };
  const auto& w = trajectory.waypoints;
  const HeldPart& held = hold(part, trajectory.grasp);
  std::size_t last = 0;  // the stretch that seats the part
  for (std::size_t i = 1; i < w.size(); ++i) last = w[i].holding ? i : last;
  std::optional<Margin> least;
  for (std::size_t i = 1; i < w.size(); ++i) {
    // Turning in its thread, the part has the thread's room (its collisions are checked).
    if (!w[i].holding || w[i].phase == "screw") continue;
    Pose to = w[i].part;
    if (i == last) {
      // Seated, the part touches what it sits on, and where faces touch flat Bullet's normal
      // says nothing of the direction: the room is measured up to a step short of the seat.
      const double length = (to.translation() - w[i - 1].part.translation()).norm();
      if (length > 0) to = sim::interpolate(w[i - 1].part, to, 1 - std::min(kShortOfSeat, length / 2) / length);
    }
    const auto c = world_.nearest_along(held.with_arm, w[i - 1].part, to, reach, counts, "part");
    if (!c || (least && c->distance >= least->distance)) continue;
    const auto name = names_.find(c->body);
    least = Margin{c->distance, name == names_.end() ? c->body_name : name->second, c->member, w[i].phase};
  }
  return least;
}

std::size_t AssemblyScene::exact_triangles(PartIndex part) const {
  const auto& mesh = product_.meshes[part];
  return mesh && !sim::pieces_are_exact(*mesh) ? mesh->triangles.size() : 0;
}

Collision AssemblyScene::to_collision(const sim::Contact& contact, const std::string& phase) const {
  const auto it = names_.find(contact.body);
  return {it == names_.end() ? contact.body_name : it->second, contact.member, contact.depth, phase};
}

}  // namespace twin
