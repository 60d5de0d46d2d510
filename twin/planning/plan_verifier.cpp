#include "twin/planning/plan_verifier.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include "sim/collision/collision_world.hpp"
#include "sim/mesh/solid.hpp"

namespace twin {
namespace {

using Triangle = std::array<Vec3, 3>;
using Kernel = sim::SolidKernel;

// A shape has its triangles looked up by box through a tree past this many.
constexpr std::size_t kTreeFrom = 64;
// m between the poses at which a violation's depth is followed along its move, and how many.
constexpr double kDepthStep = 0.001;
constexpr int kDepthPoses = 20;
// rad of the helix between the poses at which the thread is asked: a third of a turn (at half
// turns a left-hand helix stands where a right-hand one does)
constexpr double kThreadTurn = 2 * 3.14159265358979323846 / 3;

CGAL::Bbox_3 bbox(const Eigen::AlignedBox3d& b) {
  return {b.min().x(), b.min().y(), b.min().z(), b.max().x(), b.max().y(), b.max().z()};
}

Eigen::AlignedBox3d box_of(const Triangle& t) {
  Eigen::AlignedBox3d b(t[0]);
  b.extend(t[1]);
  b.extend(t[2]);
  return b;
}

// The box around a box moved by the pose.
Eigen::AlignedBox3d moved_box(const Eigen::AlignedBox3d& box, const Pose& pose) {
  if (box.isEmpty()) return box;
  const Vec3 centre = pose * box.center();
  const Vec3 half = pose.linear().cwiseAbs() * (box.sizes() / 2);
  return {centre - half, centre + half};
}

Triangle moved(Triangle t, const Pose& pose) {
  for (Vec3& v : t) v = pose * v;
  return t;
}

Kernel::Triangle_3 cgal_triangle(const Triangle& t) {
  return {{t[0].x(), t[0].y(), t[0].z()}, {t[1].x(), t[1].y(), t[1].z()}, {t[2].x(), t[2].y(), t[2].z()}};
}

// A closed shape of the replay, in its own frame: a part's mesh where it is one piece, each
// piece where the mesh is authored as convex pieces (its hull where the piece is not closed
// and convex: planning takes the hulls), a gripper's box, the station's slab.
class Shape {
 public:
  // `convex`: the mesh is one closed convex piece.
  Shape(const sim::TriangleMesh& mesh, bool convex) {
    for (const auto& t : mesh.triangles) {
      triangles_.push_back({mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]});
      boxes_.push_back(box_of(triangles_.back()));
    }
    corners_ = mesh.vertices;
    for (const Vec3& v : mesh.vertices) {
      box_.extend(v);
      radius_ = std::max(radius_, v.norm());
    }
    // The mesh is kept for a solid where one is asked for: a concave shape's depth, a large
    // one's triangle tree.
    if (!convex || triangles_.size() >= kTreeFrom) mesh_ = std::make_unique<sim::TriangleMesh>(mesh);
    if (!convex) return;
    double volume = 0;  // signed: positive when wound outwards
    for (const auto& t : triangles_) volume += t[0].dot(t[1].cross(t[2]));
    for (const auto& t : triangles_) {
      const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
      if (n.norm() < 1e-18) continue;
      const Vec3 outward = n.normalized() * (volume < 0 ? -1 : 1);
      planes_.emplace_back(outward, outward.dot(t[0]));
    }
    // A face of several triangles is one plane: every depth is a least over the planes, so
    // each is kept once (to a nanometre; a near twin left is only asked twice).
    const auto key = [](const std::pair<Vec3, double>& p) {
      return std::array<long long, 4>{std::llround(p.first.x() * 1e9), std::llround(p.first.y() * 1e9),
                                      std::llround(p.first.z() * 1e9), std::llround(p.second * 1e9)};
    };
    std::sort(planes_.begin(), planes_.end(), [&](const auto& a, const auto& b) { return key(a) < key(b); });
    planes_.erase(std::unique(planes_.begin(), planes_.end(), [&](const auto& a, const auto& b) { return key(a) == key(b); }),
                  planes_.end());
  }

  const std::vector<Triangle>& triangles() const { return triangles_; }
  const std::vector<Vec3>& corners() const { return corners_; }
  const Eigen::AlignedBox3d& box() const { return box_; }
  double radius() const { return radius_; }
  bool convex() const { return !planes_.empty(); }

  // The triangles whose boxes meet `box` (own frame).
  void near(const Eigen::AlignedBox3d& box, std::vector<std::size_t>& out) const {
    out.clear();
    if (triangles_.size() < kTreeFrom) {
      for (std::size_t i = 0; i < boxes_.size(); ++i) {
        if (boxes_[i].intersects(box)) out.push_back(i);
      }
      return;
    }
    std::vector<sim::Solid::Tree::Primitive_id> faces;
    solid().surface->all_intersected_primitives(bbox(box), std::back_inserter(faces));
    for (auto f : faces) out.push_back(static_cast<std::size_t>(f.idx()));
  }

  // A point of the triangle (own frame) inside, deeper than `floor`: the first found, or with
  // `deepest` the deepest (sim::deepest_inside). A convex shape's depth at a point is the
  // least of d - n.x over its planes, and d - n.x at the corners bounds a piece of the
  // triangle.
  std::optional<sim::DeepPoint> deeper_than(const Triangle& triangle, double floor, double resolution, bool deepest) const {
    if (!convex()) return sim::deepest_inside(solid(), triangle, floor, resolution, deepest);
    std::optional<sim::DeepPoint> found;
    std::vector<Triangle> pieces{triangle};
    while (!pieces.empty()) {
      const Triangle t = pieces.back();
      pieces.pop_back();
      double bound = std::numeric_limits<double>::infinity();
      for (const auto& [n, d] : planes_) bound = std::min(bound, std::max({d - n.dot(t[0]), d - n.dot(t[1]), d - n.dot(t[2])}));
      if (bound <= floor) continue;
      const Vec3 middle = (t[0] + t[1] + t[2]) / 3;
      double depth = std::numeric_limits<double>::infinity();
      for (const auto& [n, d] : planes_) depth = std::min(depth, d - n.dot(middle));
      if (depth > floor) {
        found = sim::DeepPoint{depth, middle};
        if (!deepest) return found;
        floor = depth + resolution;  // the deepest, to within the resolution
      }
      if (std::max({(t[0] - middle).norm(), (t[1] - middle).norm(), (t[2] - middle).norm()}) <= resolution) continue;
      const Vec3 ab = (t[0] + t[1]) / 2, bc = (t[1] + t[2]) / 2, ca = (t[2] + t[0]) / 2;
      pieces.insert(pieces.end(), {{t[0], ab, ca}, {ab, t[1], bc}, {ca, bc, t[2]}, {ab, bc, ca}});
    }
    return found;
  }

  // How deep a point (own frame) lies inside; 0 outside.
  double depth(const Vec3& p) const {
    if (!convex()) return solid().depth(p, 0);
    double depth = std::numeric_limits<double>::infinity();
    for (const auto& [n, d] : planes_) depth = std::min(depth, d - n.dot(p));
    return std::max(0.0, depth);
  }

  // Whether the shape has an inside: a mesh that is not closed has none, and what crosses
  // its surface cannot be measured.
  bool closed() const { return convex() || solid().inside != nullptr; }
  // How far a triangle (own frame) that meets the surface reaches through it: at each face it
  // meets, the lesser of how far it reaches to either side of the face's plane. One that lies
  // on the surface, or touches it, reaches through by nothing; none if it does not meet it.
  std::optional<double> crossing_depth(const Triangle& t) const {
    faces_.clear();
    solid().surface->all_intersected_primitives(cgal_triangle(t), std::back_inserter(faces_));
    if (faces_.empty()) return std::nullopt;
    const auto& m = solid().mesh;
    double deepest = 0;
    for (const auto f : faces_) {
      const auto h = m.halfedge(f);
      const auto &a = m.point(m.source(h)), &b = m.point(m.target(h)), &c = m.point(m.target(m.next(h)));
      const Vec3 p(a.x(), a.y(), a.z());
      const Vec3 n = (Vec3(b.x(), b.y(), b.z()) - p).cross(Vec3(c.x(), c.y(), c.z()) - p);
      if (n.squaredNorm() == 0) continue;
      double above = 0, below = 0;
      for (const Vec3& v : t) {
        const double d = n.normalized().dot(v - p);
        above = std::max(above, d);
        below = std::max(below, -d);
      }
      deepest = std::max(deepest, std::min(above, below));
    }
    return deepest;
  }

 private:
  const sim::Solid& solid() const {
    if (!solid_) solid_ = sim::solid_of(*mesh_);
    return *solid_;
  }

  std::unique_ptr<sim::TriangleMesh> mesh_;
  std::vector<Triangle> triangles_;
  std::vector<Vec3> corners_;
  std::vector<Eigen::AlignedBox3d> boxes_;
  Eigen::AlignedBox3d box_;
  double radius_ = 0;
  std::vector<std::pair<Vec3, double>> planes_;  // a convex shape's: outward normal n, offset d
  mutable std::unique_ptr<sim::Solid> solid_;
  mutable std::vector<sim::Solid::Tree::Primitive_id> faces_;  // kept between calls
};

sim::TriangleMesh box_mesh(const Vec3& half, const Pose& pose) {
  sim::TriangleMesh m;
  for (int i = 0; i < 8; ++i) {
    m.vertices.push_back(pose * Vec3(i & 1 ? half.x() : -half.x(), i & 2 ? half.y() : -half.y(), i & 4 ? half.z() : -half.z()));
  }
  for (const auto& f : std::vector<std::array<std::uint32_t, 4>>{
           {0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}}) {
    m.triangles.push_back({f[0], f[1], f[2]});
    m.triangles.push_back({f[0], f[2], f[3]});
  }
  return m;
}

// Whether the mesh closes a convex solid: every edge has its reverse, and every corner lies on
// the inner side of every face (a box, a prism, a wedge of a plate round a hole).
bool closed_convex(const sim::TriangleMesh& mesh) {
  if (mesh.triangles.size() < 4) return false;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) edges.emplace_back(t[k], t[(k + 1) % 3]);
  }
  std::sort(edges.begin(), edges.end());
  if (std::adjacent_find(edges.begin(), edges.end()) != edges.end()) return false;
  for (const auto& [a, b] : edges) {
    if (!std::binary_search(edges.begin(), edges.end(), std::pair{b, a})) return false;
  }
  double volume = 0;  // signed: positive when wound outwards
  const auto& v = mesh.vertices;
  for (const auto& t : mesh.triangles) volume += v[t[0]].dot(v[t[1]].cross(v[t[2]]));
  if (volume <= 0) return false;
  const double slack = 1e-9 * (mesh.bounds.isEmpty() ? 1.0 : std::max(1.0, mesh.bounds.sizes().maxCoeff()));
  for (const auto& t : mesh.triangles) {
    const Vec3 n = (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]);
    if (n.squaredNorm() == 0) continue;
    const Vec3 u = n.normalized();
    for (const Vec3& p : v) {
      if (u.dot(p - v[t[0]]) > slack) return false;
    }
  }
  return true;
}

// The mesh where it closes a convex solid, else its hull.
sim::TriangleMesh closed_or_hull(sim::TriangleMesh out) {
  if (closed_convex(out)) return out;
  using Exact = CGAL::Exact_predicates_inexact_constructions_kernel;
  std::vector<Exact::Point_3> points;
  for (const Vec3& v : out.vertices) points.emplace_back(v.x(), v.y(), v.z());
  CGAL::Surface_mesh<Exact::Point_3> hull;
  CGAL::convex_hull_3(points.begin(), points.end(), hull);
  sim::TriangleMesh h;
  std::map<CGAL::Surface_mesh<Exact::Point_3>::Vertex_index, std::uint32_t> at;
  for (auto v : hull.vertices()) {
    at[v] = static_cast<std::uint32_t>(h.vertices.size());
    const auto& p = hull.point(v);
    h.vertices.emplace_back(p.x(), p.y(), p.z());
  }
  for (auto f : hull.faces()) {
    std::vector<std::uint32_t> corners;
    for (auto v : CGAL::vertices_around_face(hull.halfedge(f), hull)) corners.push_back(at[v]);
    for (std::size_t k = 1; k + 1 < corners.size(); ++k) h.triangles.push_back({corners[0], corners[k], corners[k + 1]});
  }
  return h;
}

// Each piece of a mesh authored as pieces, as its own mesh (a triangle belongs to the piece of
// its corners): its triangles where they close a convex solid, else its hull (planning takes
// each piece's hull).
std::vector<sim::TriangleMesh> piece_meshes(const sim::TriangleMesh& mesh) {
  std::vector<sim::TriangleMesh> out(mesh.pieces.size());
  std::vector<std::pair<std::uint32_t, std::uint32_t>> at(mesh.vertices.size(), {~0u, ~0u});  // piece, index in it
  for (std::uint32_t p = 0; p < mesh.pieces.size(); ++p) {
    for (auto v : mesh.pieces[p]) {
      at[v] = {p, static_cast<std::uint32_t>(out[p].vertices.size())};
      out[p].vertices.push_back(mesh.vertices[v]);
    }
  }
  for (const auto& t : mesh.triangles) {
    const auto piece = at[t[0]].first;
    if (piece == ~0u || at[t[1]].first != piece || at[t[2]].first != piece) continue;
    out[piece].triangles.push_back({at[t[0]].second, at[t[1]].second, at[t[2]].second});
  }
  for (auto& piece : out) piece = closed_or_hull(std::move(piece));
  return out;
}

bool degenerate(const Triangle& t) { return (t[1] - t[0]).cross(t[2] - t[0]).squaredNorm() < 1e-24; }


// Whether a plane keeps the two triangles apart all along the move (they may touch it): then
// their surfaces never cross there (a finger backing away along the face it held, a face
// sliding on a face). The planes tried are the triangles' own and those through an edge of
// each.
bool stays_apart(const Triangle& t, const Vec3& shift, const Triangle& s) {
  constexpr double kTouching = 1e-7;  // m: a tenth of a micrometre
  std::array<Vec3, 11> axes;
  axes[0] = (t[1] - t[0]).cross(t[2] - t[0]);
  axes[1] = (s[1] - s[0]).cross(s[2] - s[0]);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) axes[2 + 3 * i + j] = (t[(i + 1) % 3] - t[i]).cross(s[(j + 1) % 3] - s[j]);
  }
  for (Vec3 n : axes) {
    if (n.squaredNorm() < 1e-30) continue;
    n.normalize();
    double t_lo = n.dot(t[0]), t_hi = t_lo, s_lo = n.dot(s[0]), s_hi = s_lo;
    for (int k = 1; k < 3; ++k) {
      t_lo = std::min(t_lo, n.dot(t[k]));
      t_hi = std::max(t_hi, n.dot(t[k]));
      s_lo = std::min(s_lo, n.dot(s[k]));
      s_hi = std::max(s_hi, n.dot(s[k]));
    }
    const double along = n.dot(shift);
    if (t_lo >= s_hi - kTouching && along >= -kTouching) return true;
    if (t_hi <= s_lo + kTouching && along <= kTouching) return true;
  }
  return false;
}

// Whether the triangle `s` meets the prism that triangle `t` sweeps moving by `shift` (every
// point of t + u shift, u in 0..1): it crosses one of the prism's faces, or lies inside it.
bool prism_meets(const Triangle& t, const Vec3& shift, const Triangle& s) {
  if (stays_apart(t, shift, s)) return false;
  const auto cs = cgal_triangle(s);
  const auto meets = [&](const Triangle& face) { return !degenerate(face) && CGAL::do_intersect(cgal_triangle(face), cs); };
  const Triangle end{t[0] + shift, t[1] + shift, t[2] + shift};
  if (meets(t) || meets(end)) return true;
  for (int k = 0; k < 3; ++k) {
    const Vec3 &a = t[k], &b = t[(k + 1) % 3];
    if (meets({a, b, b + shift}) || meets({a, b + shift, a + shift})) return true;
  }
  // Inside: on the inner side of the five faces (a prism with no volume has no inside).
  Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
  const double height = n.dot(shift);
  if (std::abs(height) < 1e-18) return false;
  if (height < 0) n = -n;
  const Vec3 middle = (t[0] + t[1] + t[2]) / 3 + shift / 2;
  for (const Vec3& p : s) {
    if (n.dot(p - t[0]) <= 0 || n.dot(p - end[0]) >= 0) continue;
    bool inside = true;
    for (int k = 0; k < 3 && inside; ++k) {
      const Vec3 &a = t[k], &b = t[(k + 1) % 3];
      Vec3 side = (b - a).cross(shift);
      if (side.dot(middle - a) < 0) side = -side;
      inside = side.dot(p - a) > 0;
    }
    if (inside) return true;
  }
  return false;
}

// A named group of shapes: a part (its pieces), a box of the gripper, the station.
struct Body {
  std::string name;
  const std::vector<std::unique_ptr<Shape>>* shapes;
  Pose offset = Pose::Identity();  // a moving body's, from the pose it moves by
  Eigen::AlignedBox3d box;         // own frame
};

// An obstacle where it stands, for the move checked: its box and each shape's (world).
struct Placed {
  const Body* body;
  Pose pose;
  Eigen::AlignedBox3d box;
  std::vector<Eigen::AlignedBox3d> shape_boxes;
};

class Replay {
 public:
  Replay(const LoadedProduct& product, const Plan& plan, const VerifyOptions& options)
      : product_(product), plan_(plan), options_(options) {
    if (options.stability && !options.analysis) own_stability_.emplace(product, options.stand);
    if (options.stability) stability_ = options.analysis ? options.analysis : &*own_stability_;
    // The station: a slab whose top is the assembly surface, as planning has it.
    Pose slab = Pose::Identity();
    slab.translation() = Vec3(0, -0.025, 0);
    station_shapes_.push_back(std::make_unique<Shape>(box_mesh(Vec3(1.0, 0.025, 1.0), slab), true));
    station_ = {"station", &station_shapes_, Pose::Identity(), station_shapes_.front()->box()};
  }

  Verification run() {
    placed_.assign(product_.product.parts().size(), std::nullopt);
    for (std::size_t i = 0; i < plan_.steps.size(); ++i) {
      // The plan's fixtures hold these from this step on, whatever the replay finds in it.
      held_.insert(held_.end(), plan_.steps[i].fixture.begin(), plan_.steps[i].fixture.end());
      auto violation = replay(plan_.steps[i]);
      if (!violation) violation = falls_after(plan_.steps[i]);
      if (violation) {
        violation->step = i + 1;
        result_.violations.push_back(*violation);
      }
    }
    result_.verified = result_.violations.empty() && plan_.complete;
    return std::move(result_);
  }

 private:
  const Body& part_body(PartIndex part) {
    auto [it, inserted] = parts_.try_emplace(part);
    Body& body = it->second;
    if (!inserted) return body;
    body.name = product_.product.parts()[part].name;
    const auto& mesh = product_.meshes[part];
    auto [shapes, made] = shapes_.try_emplace(mesh.get());
    if (made && mesh) {
      if (mesh->pieces.size() > 1) {
        for (const auto& own : piece_meshes(*mesh)) {
          shapes->second.push_back(std::make_unique<Shape>(own, own.triangles.size() >= 4));
        }
      } else {
        shapes->second.push_back(std::make_unique<Shape>(*mesh, mesh->convex));
      }
    }
    body.shapes = &shapes->second;
    for (const auto& s : *body.shapes) body.box.extend(s->box());
    return body;
  }

  const std::vector<Body>& gripper(double opening) {
    auto [it, inserted] = grippers_.try_emplace(opening);
    if (inserted) {
      const auto boxes = fb::gripper_boxes(options_.gripper, opening);
      it->second.shapes.resize(boxes.size());
      for (std::size_t b = 0; b < boxes.size(); ++b) {
        it->second.shapes[b].push_back(std::make_unique<Shape>(box_mesh(boxes[b].half_extents, boxes[b].pose), true));
        const std::string member = boxes[b].name.rfind("finger", 0) == 0 ? "finger" : boxes[b].name;
        it->second.bodies.push_back({member, &it->second.shapes[b], Pose::Identity(), it->second.shapes[b].front()->box()});
      }
    }
    return it->second.bodies;
  }

  std::vector<Placed> obstacles() {
    std::vector<Placed> out;
    const auto add = [&](const Body& body, const Pose& pose) {
      Placed o{&body, pose, moved_box(body.box, pose), {}};
      for (const auto& s : *body.shapes) o.shape_boxes.push_back(moved_box(s->box(), pose));
      out.push_back(std::move(o));
    };
    add(station_, Pose::Identity());
    for (PartIndex p = 0; p < placed_.size(); ++p) {
      if (placed_[p]) add(part_body(p), *placed_[p]);
    }
    return out;
  }

  std::optional<Violation> replay(const PlanStep& step) {
    const auto& parts = product_.product.parts();
    const auto& w = step.trajectory.waypoints;
    // What the gripper holds, in the held part's frame: the part, and a subassembly's other
    // members where they stand relative to it in the finished product.
    std::vector<std::pair<PartIndex, Pose>> carried{{step.part, Pose::Identity()}};
    for (PartIndex m : step.carried) carried.emplace_back(m, parts[step.part].final_pose.inverse() * parts[m].final_pose);
    std::vector<Body> holding, alone;
    for (const auto& [p, offset] : carried) {
      placed_[p].reset();
      Body held = part_body(p);
      held.offset = offset;
      holding.push_back(held);
    }
    for (const Body& g : gripper(step.trajectory.grasp.opening)) {
      alone.push_back(g);
      Body held = g;
      held.offset = step.trajectory.grasp.gripper;
      holding.push_back(held);
    }
    // Turning into its thread, the part may go into the mate by the thread's overlap.
    thread_ = {};
    if (const auto& screw = step.trajectory.screw) thread_ = {parts[step.part].name, parts[screw->mate].name, screw->overlap};
    double turned = 0;  // rad along the helix since the thread was last asked
    std::optional<Violation> found;
    std::vector<Placed> around = obstacles();
    bool released = false;
    if (!w.empty() && w.front().holding) found = at_pose(holding, w.front().part, around, w.front().phase);
    for (std::size_t i = 1; i < w.size() && !found; ++i) {
      if (!w[i].holding && !released) {
        // Let go: the part stays where the last held waypoint put it.
        released = true;
        for (const auto& [p, offset] : carried) placed_[p] = w[i - 1].part * offset;
        around = obstacles();
      }
      found = w[i].holding ? along(holding, w[i - 1].part, w[i].part, around, w[i].phase)
                           : along(alone, w[i - 1].gripper, w[i].gripper, around, w[i].phase);
      if (!found && w[i].phase == "screw") {
        turned += Eigen::Quaterniond(w[i - 1].part.linear()).angularDistance(Eigen::Quaterniond(w[i].part.linear()));
        if (turned >= kThreadTurn - 1e-9) {
          turned = 0;
          found = in_thread(holding, w[i].part, around);
        }
      }
    }
    if (!released && !w.empty()) {
      for (const auto& [p, offset] : carried) placed_[p] = w.back().part * offset;
    }
    return found;
  }

  // Turning in its thread, the part overlaps the mate by no more than the thread does in the
  // finished product (its depth and the resolution): asked every third of a turn, it tells a
  // helix off the thread's axis, pitch or hand from one on it.
  std::optional<Violation> in_thread(const std::vector<Body>& members, const Pose& pose, const std::vector<Placed>& around) {
    for (const Body& m : members) {
      if (m.name != thread_.part) continue;
      const Pose at = pose * m.offset;
      for (const Placed& o : around) {
        if (o.body->name != thread_.mate) continue;
        for (const auto& a : *m.shapes) {
          for (const auto& b : *o.body->shapes) {
            const double floor = thread_.overlap + options_.resolution;
            if (auto deep = deeper(*a, at, *b, o.pose, floor, false)) {
              return Violation{0, "screw", m.name, o.body->name, deep->depth, deep->point, {}, !a->closed() || !b->closed()};
            }
          }
        }
      }
    }
    return std::nullopt;
  }

  // Whether the parts in place stand once the arm has let go of the step's part: its
  // fastenings made if the step holds it until they are, else not yet. Those between the
  // members of a subassembly it sets in place were made when it was built.
  std::optional<Violation> falls_after(const PlanStep& step) {
    if (!stability_) return std::nullopt;
    const auto& connections = product_.product.connections();
    std::vector<PlacedPart> placed;
    for (PartIndex p = 0; p < placed_.size(); ++p) {
      if (placed_[p]) placed.push_back({p, *placed_[p]});
    }
    std::vector<bool> moved(placed_.size(), false);
    moved[step.part] = true;
    for (PartIndex m : step.carried) moved[m] = true;
    std::vector<bool> fastened(connections.size(), false);
    for (std::size_t c = 0; c < connections.size(); ++c) {
      const Connection& k = connections[c];
      fastened[c] = k.joint.fastens() && placed_[k.part1] && placed_[k.part2];
      const bool made_now = moved[k.part1] != moved[k.part2];
      if (!step.hold && made_now) fastened[c] = false;
    }
    const auto falls = stability_->check(placed, held_, fastened);
    if (!falls) return std::nullopt;
    Violation v;
    v.phase = "release";
    v.member = product_.product.parts()[step.part].name;
    v.falls = describe(product_.product, *falls, options_.stand);
    return v;
  }

  // The first member at `pose` that goes into an obstacle past the tolerance, how deep.
  std::optional<Violation> at_pose(const std::vector<Body>& members, const Pose& pose, const std::vector<Placed>& around,
                                   const std::string& phase) {
    ++result_.poses;
    for (const Body& m : members) {
      const Pose at = pose * m.offset;
      const Eigen::AlignedBox3d box = moved_box(m.box, at);
      for (const Placed& o : around) {
        if (!box.intersects(o.box)) continue;
        // Turning in its thread, the part overlaps its mate by the thread: that pair is asked
        // every third of a turn (in_thread), not here.
        if (phase == "screw" && m.name == thread_.part && o.body->name == thread_.mate) continue;
        shapes_near(o, box);
        for (const auto& a : *m.shapes) {
          const Eigen::AlignedBox3d a_box = moved_box(a->box(), at);
          if (!a_box.intersects(o.box)) continue;
          for (std::size_t k : obstacle_shapes_) {
            if (!a_box.intersects(o.shape_boxes[k])) continue;
            const Shape& b = *(*o.body->shapes)[k];
            if (auto deep = deeper(*a, at, b, o.pose, options_.contact_tolerance, o.body == &station_)) {
              return Violation{0, phase, m.name, o.body->name, deep->depth, deep->point, {}, !a->closed() || !b.closed()};
            }
          }
        }
      }
    }
    return std::nullopt;
  }

  // A point of either shape inside the other (world) deeper than `floor`: the first found, or
  // with `deepest` the deepest. The station's slab is asked one way (`b_one_way`): its faces
  // are two metres wide, and a part reaches into it only by its own surface.
  std::optional<sim::DeepPoint> deeper(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double floor,
                                       bool b_one_way, bool deepest = false) {
    std::optional<sim::DeepPoint> found;
    for (int way = 0; way < (b_one_way ? 1 : 2); ++way) {
      const Shape& x = way ? b : a;
      const Shape& y = way ? a : b;
      const Pose& py = way ? pa : pb;
      const Pose to_y = py.inverse() * (way ? pb : pa);
      // x's triangles near y, in y's frame.
      x.near(moved_box(y.box(), to_y.inverse()), near_);
      const bool measurable = y.closed();
      for (std::size_t i : near_) {
        const Triangle t = moved(x.triangles()[i], to_y);
        if (!measurable) {
          // No inside to measure: a surface reaching through it past the floor counts.
          const auto through = degenerate(t) ? std::nullopt : y.crossing_depth(t);
          if (through && *through > floor) {
            found = sim::DeepPoint{*through, py * ((t[0] + t[1] + t[2]) / 3)};
            if (!deepest) return found;
            floor = *through + options_.resolution;
          }
          continue;
        }
        if (const auto deep = y.deeper_than(t, floor, options_.resolution, deepest)) {
          found = sim::DeepPoint{deep->depth, py * deep->point};
          if (!deepest) return found;
          floor = deep->depth + options_.resolution;
        }
      }
    }
    return found;
  }

  // Whether any member's surface can meet an obstacle's while the members translate by
  // `shift` (world) from `pose`.
  bool may_touch(const std::vector<Body>& members, const Pose& pose, const Vec3& shift, const std::vector<Placed>& around) {
    ++result_.sweeps;
    const auto swept = [&](Eigen::AlignedBox3d box) {
      box.extend(box.min() + shift);
      box.extend(box.max() + shift);
      return box;
    };
    for (const Body& m : members) {
      const Pose at = pose * m.offset;
      const Eigen::AlignedBox3d m_swept = swept(moved_box(m.box, at));
      for (const Placed& o : around) {
        if (!m_swept.intersects(o.box)) continue;
        shapes_near(o, m_swept);
        for (const auto& a : *m.shapes) {
          const Eigen::AlignedBox3d a_swept = swept(moved_box(a->box(), at));
          if (!a_swept.intersects(o.box)) continue;
          for (std::size_t k : obstacle_shapes_) {
            if (a_swept.intersects(o.shape_boxes[k]) && sweep_meets(*a, at, shift, *(*o.body->shapes)[k], o.pose)) return true;
          }
        }
      }
    }
    return false;
  }

  // The obstacle's shapes whose boxes meet `box` (world), into obstacle_shapes_.
  void shapes_near(const Placed& o, const Eigen::AlignedBox3d& box) {
    obstacle_shapes_.clear();
    for (std::size_t k = 0; k < o.shape_boxes.size(); ++k) {
      if (box.intersects(o.shape_boxes[k])) obstacle_shapes_.push_back(k);
    }
  }

  bool sweep_meets(const Shape& a, const Pose& at, const Vec3& shift, const Shape& b, const Pose& pb) {
    const Pose to_b = pb.inverse() * at;
    const Vec3 shift_b = pb.linear().transpose() * shift;
    // a's triangles whose sweep comes within b's box, in a's frame.
    Eigen::AlignedBox3d near = moved_box(b.box(), to_b.inverse());
    const Vec3 back = -(to_b.linear().transpose() * shift_b);
    near.extend(near.min() + back);
    near.extend(near.max() + back);
    a.near(near, near_);
    for (std::size_t i : near_) {
      const Triangle t = moved(a.triangles()[i], to_b);
      Eigen::AlignedBox3d prism = box_of(t);
      prism.extend(prism.min() + shift_b);
      prism.extend(prism.max() + shift_b);
      b.near(prism, against_);
      for (std::size_t j : against_) {
        if (prism_meets(t, shift_b, b.triangles()[j])) return true;
      }
    }
    return false;
  }

  std::optional<Violation> along(const std::vector<Body>& members, const Pose& from, const Pose& to,
                                 const std::vector<Placed>& around, const std::string& phase) {
    const auto radius_of = [](const Body& m) {
      double radius = 0;
      for (const auto& s : *m.shapes) radius = std::max(radius, m.offset.translation().norm() + s->radius());
      return radius;
    };
    double radius = 0;
    for (const Body& m : members) radius = std::max(radius, radius_of(m));
    const double angle = Eigen::Quaterniond(from.linear()).angularDistance(Eigen::Quaterniond(to.linear()));
    const Vec3 shift = to.translation() - from.translation();
    const double travel = shift.norm() + angle * radius;
    const double step = options_.resolution;
    if (angle > 1e-12) {
      // Turning: pose by pose, no point of a member moving more than the resolution between
      // them (each member at its own poses: the part near the axis needs far fewer than the
      // gripper's carriage). A run of poses whose swept box (both ends' boxes, grown by how far
      // the turn moves a point) meets no obstacle's is clear whole; the rest is halved.
      for (const Body& m : members) {
        const double reach = radius_of(m);
        const int n = std::max(1, static_cast<int>(std::ceil((shift.norm() + angle * reach) / step)));
        const auto pose_at = [&](int k) { return sim::interpolate(from, to, double(k) / n); };
        const auto may_meet = [&](int k0, int k1) {
          Eigen::AlignedBox3d box = moved_box(m.box, pose_at(k0) * m.offset);
          box.extend(moved_box(m.box, pose_at(k1) * m.offset));
          const double grow = angle * reach * (k1 - k0) / n;
          box.min().array() -= grow;
          box.max().array() += grow;
          return std::any_of(around.begin(), around.end(), [&](const Placed& o) {
            return !(phase == "screw" && m.name == thread_.part && o.body->name == thread_.mate) && box.intersects(o.box);
          });
        };
        std::optional<Violation> v;
        const auto check = [&](auto&& self, int k0, int k1) -> bool {  // poses k0+1..k1; true: clear
          if (!may_meet(k0, k1)) return true;
          if (k1 - k0 == 1) return !(v = at_pose({m}, pose_at(k1), around, phase));
          const int mid = (k0 + k1) / 2;
          return self(self, k0, mid) && self(self, mid, k1);
        };
        if (!check(check, 0, n)) return v;
      }
      return std::nullopt;
    }
    // Straight: a stretch along which no surface can meet another is clear whole; one where
    // they may is halved, down to the resolution, and its poses measured. The pose at `s0`
    // is known clear.
    std::optional<Violation> found;
    double at = 0;  // where along the move the first violation is
    const auto check = [&](auto&& self, double s0, double s1) -> bool {
      if (!may_touch(members, sim::interpolate(from, to, s0), shift * (s1 - s0), around)) return true;
      if ((s1 - s0) * travel <= step) {
        found = at_pose(members, sim::interpolate(from, to, s1), around, phase);
        at = s1;
        return !found;
      }
      const double mid = (s0 + s1) / 2;
      return self(self, s0, mid) && self(self, mid, s1);
    };
    if (travel > step) {
      // Most moves touch only where they end (a part set down on its seat): the end pose is
      // measured, and the rest, up to one step short of it, swept whole.
      const double last = 1 - step / travel;
      if (!(found = at_pose(members, to, around, phase))) {
        if (may_touch(members, from, shift * last, around)) {
          check(check, 0.0, last);
        }
      } else {
        at = 1;
        check(check, 0.0, 1.0);  // where along the move it begins
      }
    } else if (travel > 0) {
      check(check, 0.0, 1.0);
    }
    if (found) deepest_after(*found, members, from, to, at, travel, around);
    return found;
  }

  // A violation is found where it begins, barely past the tolerance; the designer wants to
  // know how deep the move goes. The rest of the move is sampled (every millimetre, at most
  // kDepthPoses poses) and at each pose the corners of either shape inside the other are
  // measured: the depth said is the deepest found, a least one.
  void deepest_after(Violation& v, const std::vector<Body>& members, const Pose& from, const Pose& to, double at,
                     double travel, const std::vector<Placed>& around) {
    const int n = std::min(kDepthPoses, static_cast<int>(std::ceil((1 - at) * travel / kDepthStep)));
    for (int k = 0; k <= n; ++k) {
      const Pose pose = sim::interpolate(from, to, n == 0 ? at : at + (1 - at) * k / n);
      for (const Body& m : members) {
        if (m.name != v.member) continue;
        const Pose p = pose * m.offset;
        for (const Placed& o : around) {
          if (o.body->name != v.with || !moved_box(m.box, p).intersects(o.box)) continue;
          for (const auto& a : *m.shapes) {
            for (const auto& b : *o.body->shapes) {
              deepest_corner(*a, p, *b, o.pose, v);
              if (o.body != &station_) deepest_corner(*b, o.pose, *a, p, v);
            }
          }
        }
      }
    }
  }

  // The corners of x that lie in y deeper than the violation says.
  void deepest_corner(const Shape& x, const Pose& px, const Shape& y, const Pose& py, Violation& v) {
    const Pose to_y = py.inverse() * px;
    const Eigen::AlignedBox3d box = y.box();
    for (const Vec3& corner : x.corners()) {
      const Vec3 c = to_y * corner;
      if (!box.contains(c)) continue;
      const double depth = y.depth(c);
      if (depth > v.depth) {
        v.depth = depth;
        v.where = py * c;
      }
    }
  }

  const LoadedProduct& product_;
  const Plan& plan_;
  const VerifyOptions& options_;
  Verification result_;
  std::vector<std::unique_ptr<Shape>> station_shapes_;
  Body station_;
  std::map<const sim::TriangleMesh*, std::vector<std::unique_ptr<Shape>>> shapes_;
  std::map<PartIndex, Body> parts_;
  struct Gripper {
    std::vector<std::vector<std::unique_ptr<Shape>>> shapes;
    std::vector<Body> bodies;
  };
  std::map<double, Gripper> grippers_;
  std::vector<std::optional<Pose>> placed_;
  std::vector<std::size_t> near_, against_, obstacle_shapes_;  // kept between calls: no allocation per query
  std::optional<StabilityAnalysis> own_stability_;
  const StabilityAnalysis* stability_ = nullptr;
  std::vector<PartIndex> held_;  // by the plan's fixtures
  struct {
    std::string part, mate;  // the step's part turned into the mate's thread (Trajectory::screw)
    double overlap = 0;      // m, the thread's in the finished product
  } thread_;
};

}  // namespace

std::string describe(const Product& product, const Violation& v) {
  (void)product;
  if (!v.falls.empty()) return "step " + std::to_string(v.step) + ": when the arm lets go, " + v.falls;
  char depth[32];
  std::snprintf(depth, sizeof depth, "%.2f mm", v.depth * 1000);
  const bool part = v.member != "finger" && v.member != "palm" && v.member != "carriage";
  return "step " + std::to_string(v.step) + ": the " + (part ? v.member : "gripper's " + v.member) + " went " + depth +
         (v.open_surface ? " through an open surface of " : " into ") + v.with + " while " + v.phase;
}

Verification verify_plan(const LoadedProduct& product, const Plan& plan, const VerifyOptions& options) {
  return Replay(product, plan, options).run();
}

}  // namespace twin
