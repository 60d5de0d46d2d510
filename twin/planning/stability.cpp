#include "twin/planning/stability.hpp"

#include <algorithm>
#include <cmath>
#include <array>
#include <cstdio>
#include <numeric>

#include <ClpSimplex.hpp>
#include <CoinPackedMatrix.hpp>

#include "sim/mesh/solid.hpp"

namespace twin {
namespace {

// The linear program works in centimetres (lengths) and cubic centimetres (masses of a density
// of one): numbers near one for parts of a few centimetres, which the simplex likes better than
// metres.
constexpr double kCm = 100;
constexpr int kPyramidEdges = 4;           // a friction cone as a pyramid of four edges
constexpr std::size_t kPointsPerPatch = 6;   // the corners kept of a contact patch
constexpr double kSameNormal = 0.87;       // cos 30 degrees: contacts of one patch

// A contact in the frame of the part it is stored with: where, and the direction in which the
// other part is pushed (out of this one's surface).
struct ContactPoint {
  Vec3 point;
  Vec3 normal;
};

struct PartFacts {
  double volume = 0;            // m^3
  Vec3 centre = Vec3::Zero();   // of mass, own frame
  double orientation = 1;       // -1: the mesh is wound inwards
  std::vector<Eigen::AlignedBox3d> boxes;  // of its triangles, own frame
  std::unique_ptr<sim::Solid> solid;  // for distances, made when first asked
};

// The corners of a set of contacts that share a normal: the convex hull of the points in the
// plane across the normal, thinned to kPointsPerPatch by farthest points. Force and moment
// balance need only the hull of a patch.
std::vector<ContactPoint> patch_corners(const std::vector<ContactPoint>& patch) {
  if (patch.size() <= 3) return patch;
  Vec3 n = Vec3::Zero();
  for (const auto& c : patch) n += c.normal;
  n.normalize();
  const Vec3 u = n.unitOrthogonal(), v = n.cross(u);
  std::vector<std::size_t> order(patch.size());
  std::iota(order.begin(), order.end(), 0);
  std::vector<Eigen::Vector2d> in_plane(patch.size());
  for (std::size_t i = 0; i < patch.size(); ++i) in_plane[i] = {u.dot(patch[i].point), v.dot(patch[i].point)};
  const auto uv = [&](std::size_t i) -> const Eigen::Vector2d& { return in_plane[i]; };
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const auto &pa = uv(a), &pb = uv(b);
    return pa.x() < pb.x() || (pa.x() == pb.x() && pa.y() < pb.y());
  });
  // Andrew's monotone chain.
  const auto cross = [&](std::size_t o, std::size_t a, std::size_t b) {
    const auto &po = uv(o), &pa = uv(a), &pb = uv(b);
    return (pa.x() - po.x()) * (pb.y() - po.y()) - (pa.y() - po.y()) * (pb.x() - po.x());
  };
  std::vector<std::size_t> hull(2 * order.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], order[i]) <= 0) --k;
    hull[k++] = order[i];
  }
  for (std::size_t i = order.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], order[i]) <= 0) --k;
    hull[k++] = order[i];
  }
  hull.resize(k > 1 ? k - 1 : k);
  if (hull.empty()) return {patch.front()};
  // Farthest points, from the first corner.
  std::vector<std::size_t> kept{hull.front()};
  std::vector<double> nearest(hull.size(), std::numeric_limits<double>::infinity());
  while (kept.size() < std::min(kPointsPerPatch, hull.size())) {
    std::size_t farthest = 0;
    for (std::size_t i = 0; i < hull.size(); ++i) {
      nearest[i] = std::min(nearest[i], (patch[hull[i]].point - patch[kept.back()].point).squaredNorm());
      if (nearest[i] > nearest[farthest]) farthest = i;
    }
    if (nearest[farthest] == 0) break;
    kept.push_back(hull[farthest]);
  }
  std::vector<ContactPoint> out;
  for (std::size_t i : kept) out.push_back({patch[i].point, n});
  return out;
}

// Contacts grouped into patches of one normal, each reduced to its corners.
std::vector<ContactPoint> reduce(const std::vector<ContactPoint>& contacts) {
  std::vector<std::vector<ContactPoint>> patches;
  for (const auto& c : contacts) {
    auto it = std::find_if(patches.begin(), patches.end(),
                           [&](const auto& p) { return p.front().normal.dot(c.normal) > kSameNormal; });
    if (it == patches.end()) {
      patches.push_back({c});
    } else {
      it->push_back(c);
    }
  }
  std::vector<ContactPoint> out;
  for (const auto& p : patches) {
    const auto corners = patch_corners(p);
    out.insert(out.end(), corners.begin(), corners.end());
  }
  return out;
}

// A pose as a key: its rotation and translation (the top three rows of its matrix; the first
// twelve numbers of the 4x4 column-major storage would leave the translation out).
std::array<double, 12> key_of(const Pose& pose) {
  std::array<double, 12> key;
  Eigen::Map<Eigen::Matrix<double, 3, 4>>(key.data()) = pose.affine();
  return key;
}

}  // namespace

struct StabilityAnalysis::Impl {
  const LoadedProduct& product;
  StabilityOptions options;
  mutable std::map<PartIndex, PartFacts> facts;
  // Contacts of each pair (a < b) where they stand in the finished product, in a's frame, the
  // normal the way b is pushed.
  mutable std::map<std::pair<PartIndex, PartIndex>, std::vector<ContactPoint>> pairs;
  mutable std::map<std::vector<double>, std::optional<Instability>> answers;  // check(), by state
  // on_station(), by part and pose (key_of)
  mutable std::map<std::pair<PartIndex, std::array<double, 12>>, std::vector<ContactPoint>> stations;

  const PartFacts& facts_of(PartIndex p) const {
    auto [it, made] = facts.try_emplace(p);
    PartFacts& f = it->second;
    if (!made) return f;
    const auto& mesh = product.meshes[p];
    if (!mesh) return f;
    double volume = 0;
    Vec3 moment = Vec3::Zero();
    for (const auto& t : mesh->triangles) {
      const Vec3 &a = mesh->vertices[t[0]], &b = mesh->vertices[t[1]], &c = mesh->vertices[t[2]];
      const double v = a.dot(b.cross(c)) / 6;
      volume += v;
      moment += v * (a + b + c) / 4;
      f.boxes.emplace_back(a);
      f.boxes.back().extend(b);
      f.boxes.back().extend(c);
    }
    f.orientation = volume < 0 ? -1 : 1;
    if (mesh->repairs.open_edges == 0 && std::abs(volume) > 0) {
      f.volume = std::abs(volume);
      f.centre = moment / volume;
    } else {  // no inside (an open mesh): its box stands for it
      f.volume = mesh->bounds.volume();
      f.centre = mesh->bounds.center();
    }
    return f;
  }

  const sim::Solid& solid_of(PartIndex p) const {
    const PartFacts& f = facts_of(p);
    if (!f.solid) facts.at(p).solid = sim::solid_of(*product.meshes[p]);
    return *f.solid;
  }

  // The corners of x within the contact distance of y's surface (x, y at their final poses), as
  // contacts in a's frame. Corners only: a patch whose corners are those of the two faces
  // that meet is seen whole; one cut by an edge of the other face is seen smaller, which is
  // the safe side.
  void near_surface(PartIndex x, PartIndex y, PartIndex a, bool pushes_b, std::vector<ContactPoint>& out) const {
    const auto& parts = product.product.parts();
    const sim::Solid& fy = solid_of(y);
    const Pose x_to_y = parts[y].final_pose.inverse() * parts[x].final_pose;
    const Pose y_to_a = parts[a].final_pose.inverse() * parts[y].final_pose;
    Eigen::AlignedBox3d near = product.meshes[y]->bounds;
    const Vec3 grow = Vec3::Constant(options.contact_distance);
    near.extend(near.min() - grow);
    near.extend(near.max() + grow);
    for (const Vec3& s : product.meshes[x]->vertices) {
      const Vec3 p = x_to_y * s;
      if (!near.contains(p)) continue;
      const sim::SolidPoint q(p.x(), p.y(), p.z());
      const auto [nearest, face] = fy.surface->closest_point_and_primitive(q);
      if (std::sqrt(CGAL::squared_distance(q, nearest)) > options.contact_distance) continue;
      const auto h = fy.mesh.halfedge(face);
      const auto& m = fy.mesh;
      const auto &fa = m.point(m.source(h)), &fb = m.point(m.target(h)), &fc = m.point(m.target(m.next(h)));
      const auto n3 = CGAL::cross_product(fb - fa, fc - fa);
      Vec3 n(n3.x(), n3.y(), n3.z());
      if (n.norm() == 0) continue;
      // Only where the nearest point lies inside a face: at an edge or a corner the face that
      // happens to be nearest says nothing of the way it pushes (an edge of a box beside
      // another would push it up). Flat patches are found whole by flat_patches.
      const double area2 = n3.squared_length();
      const double u = CGAL::cross_product(fc - fb, nearest - fb) * n3 / area2,
                   v = CGAL::cross_product(fa - fc, nearest - fc) * n3 / area2;
      constexpr double kInside = 1e-3;
      if (u <= kInside || v <= kInside || 1 - u - v <= kInside) continue;
      n = n.normalized() * fy.orientation;  // out of y
      // y pushes x along n: the way b is pushed is n where x is b, -n where x is a.
      out.push_back({y_to_a * Vec3(nearest.x(), nearest.y(), nearest.z()), y_to_a.linear() * (pushes_b ? n : Vec3(-n))});
    }
  }

  // Where a face of b rests flat on a face of a (in one plane, facing each other), the corners
  // of the patch they share: b's triangle clipped by a's (Sutherland-Hodgman, in a's plane).
  // Two boxes crossed at right angles share a patch whose corners are neither's.
  void flat_patches(PartIndex a, PartIndex b, std::vector<ContactPoint>& out) const {
    const auto& parts = product.product.parts();
    const PartFacts& fa = facts_of(a);
    const auto& ma = *product.meshes[a];
    const auto& mb = *product.meshes[b];
    const Pose b_to_a = parts[a].final_pose.inverse() * parts[b].final_pose;
    const Vec3 grow = Vec3::Constant(options.contact_distance);
    // Each mesh's triangles near the other's box (grown by the contact distance), in a's frame,
    // with their boxes: asked by their boxes in their own frame first.
    const auto near = [&](PartIndex p, const Pose& to_a, const Eigen::AlignedBox3d& other_in_a) {
      const sim::TriangleMesh& m = *product.meshes[p];
      const PartFacts& f = facts_of(p);
      Eigen::AlignedBox3d box = other_in_a;
      box.extend(box.min() - grow);
      box.extend(box.max() + grow);
      const Eigen::AlignedBox3d own = box.transformed(to_a.inverse());
      std::vector<std::pair<std::array<Vec3, 3>, Eigen::AlignedBox3d>> found;
      for (std::size_t i = 0; i < m.triangles.size(); ++i) {
        if (!f.boxes[i].intersects(own)) continue;
        const auto& tri = m.triangles[i];
        const std::array<Vec3, 3> t{to_a * m.vertices[tri[0]], to_a * m.vertices[tri[1]], to_a * m.vertices[tri[2]]};
        Eigen::AlignedBox3d tb(t[0]);
        tb.extend(t[1]);
        tb.extend(t[2]);
        if (tb.intersects(box)) found.emplace_back(t, tb);
      }
      return found;
    };
    const auto of_b = near(b, b_to_a, ma.bounds);
    if (of_b.empty()) return;
    const auto of_a = near(a, Pose::Identity(), mb.bounds.transformed(b_to_a));
    const auto outward = [](const std::array<Vec3, 3>& t, double orientation) {
      const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
      return n.norm() == 0 ? Vec3(Vec3::Zero()) : Vec3(n.normalized() * orientation);
    };
    // a's faces by the x of their outward normal: a face of b can face only those whose
    // normal's x is within kFacing of the opposite of its own.
    constexpr double kFacingCos = -0.999;
    const double kFacing = std::sqrt(2 * (1 + kFacingCos));  // |n + nb| at that angle
    std::vector<std::pair<Vec3, std::size_t>> a_normals;  // (out of a, index in of_a)
    for (std::size_t i = 0; i < of_a.size(); ++i) {
      const Vec3 n = outward(of_a[i].first, fa.orientation);
      if (!n.isZero()) a_normals.emplace_back(n, i);
    }
    std::sort(a_normals.begin(), a_normals.end(), [](const auto& x, const auto& y) { return x.first.x() < y.first.x(); });
    const double b_orientation = facts_of(b).orientation;
    for (const auto& [t, tb] : of_b) {
      const Vec3 nb = outward(t, b_orientation);
      if (nb.isZero()) continue;
      Eigen::AlignedBox3d reach = tb;
      reach.extend(reach.min() - grow);
      reach.extend(reach.max() + grow);
      const auto first = std::lower_bound(a_normals.begin(), a_normals.end(), -nb.x() - kFacing,
                                          [](const auto& x, double v) { return x.first.x() < v; });
      for (auto it = first; it != a_normals.end() && it->first.x() <= -nb.x() + kFacing; ++it) {
        const Vec3& n = it->first;
        // Facing each other (b's face looks into a), in one plane to the contact distance.
        if (nb.dot(n) > kFacingCos) continue;
        const auto& [f, fb] = of_a[it->second];
        if (!reach.intersects(fb)) continue;
        if (std::abs(n.dot(t[0] - f[0])) > options.contact_distance || std::abs(n.dot(t[1] - f[0])) > options.contact_distance ||
            std::abs(n.dot(t[2] - f[0])) > options.contact_distance) {
          continue;
        }
        const Vec3 wound = (f[1] - f[0]).cross(f[2] - f[0]);
        // A triangle cut by three lines has at most six corners.
        std::array<Vec3, 6> polygon{t[0], t[1], t[2]}, kept;
        std::size_t corners = 3;
        for (std::size_t i = 0; i < corners; ++i) polygon[i] -= n * n.dot(polygon[i] - f[0]);  // into a's plane
        for (int k = 0; k < 3 && corners > 0; ++k) {
          const Vec3 &e0 = f[k], &e1 = f[(k + 1) % 3];
          const Vec3 inward = wound.cross(e1 - e0);  // towards the inside of a's triangle
          std::size_t left = 0;
          for (std::size_t i = 0; i < corners; ++i) {
            const Vec3 &p = polygon[i], &q = polygon[(i + 1) % corners];
            const double dp = inward.dot(p - e0), dq = inward.dot(q - e0);
            if (dp >= 0 && left < kept.size()) kept[left++] = p;
            if ((dp >= 0) != (dq >= 0) && left < kept.size()) kept[left++] = p + (q - p) * (dp / (dp - dq));
          }
          polygon = kept;
          corners = left;
        }
        for (std::size_t i = 0; i < corners; ++i) out.push_back({polygon[i], n});
      }
    }
  }

  const std::vector<ContactPoint>& contacts(PartIndex a, PartIndex b) const {
    auto [it, made] = pairs.try_emplace({a, b});
    if (!made) return it->second;
    const auto& meshes = product.meshes;
    if (!meshes[a] || !meshes[b]) return it->second;
    const auto& parts = product.product.parts();
    Eigen::AlignedBox3d box_b = meshes[b]->bounds.transformed(parts[a].final_pose.inverse() * parts[b].final_pose);
    Eigen::AlignedBox3d box_a = meshes[a]->bounds;
    const Vec3 grow = Vec3::Constant(options.contact_distance);
    box_a.extend(box_a.min() - grow);
    box_a.extend(box_a.max() + grow);
    if (!box_a.intersects(box_b)) return it->second;
    // Faces resting on faces; where there are none, corners on faces (a cylinder lying on a
    // plane, a tilted part): asking every corner costs a distance each.
    std::vector<ContactPoint> all;
    flat_patches(a, b, all);
    if (all.empty()) {
      near_surface(b, a, a, true, all);   // b's corners on a: a pushes b out of itself
      near_surface(a, b, a, false, all);  // a's corners on b: b pushes a, so b is pushed the other way
    }
    it->second = reduce(all);
    return it->second;
  }

  // Contacts of a part with the station's surface (y = 0) where it stands at `pose`: its
  // corners that lie within the contact distance of it, in the world, pushed up.
  const std::vector<ContactPoint>& on_station(PartIndex p, const Pose& pose) const {
    auto [it, made] = stations.try_emplace({p, key_of(pose)});
    if (!made || !product.meshes[p]) return it->second;
    std::vector<ContactPoint> out;
    for (const Vec3& v : product.meshes[p]->vertices) {
      const Vec3 w = pose * v;
      if (w.y() <= options.contact_distance) out.push_back({Vec3(w.x(), 0, w.z()), Vec3::UnitY()});
    }
    it->second = reduce(out);
    return it->second;
  }
};

StabilityAnalysis::StabilityAnalysis(const LoadedProduct& product, StabilityOptions options)
    : impl_(std::make_unique<Impl>(Impl{product, options, {}, {}, {}, {}})), options_(options) {}

StabilityAnalysis::~StabilityAnalysis() = default;

// The parts in place as bodies: rigid groups that may move (not fixed, not fastened to a
// fixed part), their weights and centres, and every contact between them and with what stands
// still: the station and fixed groups (-1), and groups assumed to stand still whose bearing is
// counted (-2).
struct StabilityAnalysis::State {
  struct Contact {
    int on, from;  // pushed, and pushing back (a body, -1 or -2)
    Vec3 point, normal;
  };
  std::vector<std::vector<PartIndex>> bodies;
  std::vector<double> mass;  // m^3 of one density
  std::vector<Vec3> centre;
  std::vector<Contact> contacts;
};

StabilityAnalysis::State StabilityAnalysis::state(const std::vector<PlacedPart>& placed,
                                                  const std::vector<PartIndex>& fixed,
                                                  const std::vector<PartIndex>& assumed,
                                                  const std::vector<bool>& fastened) const {
  State out;
  const auto& connections = impl_->product.product.connections();
  std::map<PartIndex, std::size_t> slot;  // part -> its place in `placed`
  for (std::size_t i = 0; i < placed.size(); ++i) slot[placed[i].part] = i;
  std::vector<std::size_t> group(placed.size());
  std::iota(group.begin(), group.end(), 0);
  const auto root = [&](std::size_t i) {
    while (group[i] != i) i = group[i] = group[group[i]];
    return i;
  };
  for (std::size_t c = 0; c < connections.size(); ++c) {
    if (c >= fastened.size() || !fastened[c]) continue;
    const auto a = slot.find(connections[c].part1), b = slot.find(connections[c].part2);
    if (a != slot.end() && b != slot.end()) group[root(a->second)] = root(b->second);
  }
  std::vector<int> still(placed.size(), 0);
  for (const auto& [list, mark] : {std::pair{&fixed, -1}, std::pair{&assumed, -2}}) {
    for (PartIndex p : *list) {
      if (const auto it = slot.find(p); it != slot.end() && still[root(it->second)] != -1) still[root(it->second)] = mark;
    }
  }
  std::map<std::size_t, int> body_of_group;
  for (std::size_t i = 0; i < placed.size(); ++i) {
    const std::size_t g = root(i);
    if (still[g] < 0) continue;
    auto [it, fresh] = body_of_group.try_emplace(g, static_cast<int>(out.bodies.size()));
    if (fresh) out.bodies.emplace_back();
    out.bodies[static_cast<std::size_t>(it->second)].push_back(placed[i].part);
  }
  const auto body_of = [&](std::size_t i) {
    const auto it = body_of_group.find(root(i));
    return it == body_of_group.end() ? still[root(i)] : it->second;
  };
  out.mass.assign(out.bodies.size(), 0);
  out.centre.assign(out.bodies.size(), Vec3::Zero());
  for (std::size_t i = 0; i < placed.size(); ++i) {
    const int b = body_of(i);
    if (b < 0) continue;
    const PartFacts& f = impl_->facts_of(placed[i].part);
    out.mass[b] += f.volume;
    out.centre[b] += f.volume * (placed[i].pose * f.centre);
  }
  for (std::size_t b = 0; b < out.bodies.size(); ++b) {
    if (out.mass[b] > 0) out.centre[b] /= out.mass[b];
  }
  for (std::size_t i = 0; i < placed.size(); ++i) {
    const int bi = body_of(i);
    if (bi >= 0) {
      for (const auto& c : impl_->on_station(placed[i].part, placed[i].pose)) out.contacts.push_back({bi, -1, c.point, c.normal});
    }
    for (std::size_t j = i + 1; j < placed.size(); ++j) {
      const int bj = body_of(j);
      if (root(i) == root(j) || (bi < 0 && bj < 0)) continue;
      PartIndex a = placed[i].part, b = placed[j].part;
      int ba = bi, bb = bj;
      std::size_t ia = i;
      if (a > b) {
        std::swap(a, b);
        std::swap(ba, bb);
        ia = j;
      }
      const Pose& pa = placed[ia].pose;
      for (const auto& c : impl_->contacts(a, b)) out.contacts.push_back({bb, ba, pa * c.point, pa.linear() * c.normal});
    }
  }
  return out;
}

namespace {

// A contact bears (carries weight, with friction) where its normal is within 45 degrees of up;
// a steeper one pushes along its normal only. Friction on a side wall would let a part in a
// hole with clearance hang by wedging, which no real part does (a press fit is a joint).
constexpr double kBears = 0.7071;

// The gravities asked: tilted by `tilt` degrees every way (the gravities contact forces can
// balance form a convex cone, which then holds upright too), or upright.
std::vector<Vec3> gravities(double tilt, int ways) {
  if (tilt == 0) return {-Vec3::UnitY()};
  std::vector<Vec3> out;
  const double t = tilt * M_PI / 180;
  for (int d = 0; d < ways; ++d) {
    const double around = 2 * M_PI * d / ways;
    out.emplace_back(std::sin(t) * std::cos(around), -std::cos(t), std::sin(t) * std::sin(around));
  }
  return out;
}

// Whether the point lies inside the convex hull of the points (2D), by the hull's edges.
bool inside_hull(std::vector<Eigen::Vector2d> points, const Eigen::Vector2d& q) {
  if (points.size() < 3) return false;
  std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  const auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  std::size_t k = 0;
  for (const auto& p : points) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p) <= 0) --k;
    hull[k++] = p;
  }
  for (std::size_t i = points.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  if (k < 4) return false;
  for (std::size_t i = 0; i + 1 < k; ++i) {
    if (cross(hull[i], hull[i + 1], q) <= 0) return false;
  }
  return true;
}

}  // namespace

// Parts stacked: where every body bears on one thing only (the station, a fixed group, or one
// other body) through contacts that face up within atan(friction) - tilt, each body carries
// the weight of what rests on it straight down, and stands where the line of that weight
// through its centre meets its bearing contacts' hull, for every gravity asked. A sufficient
// test: true means it stands; false, that the linear program must tell.
bool StabilityAnalysis::stacked(const State& s, double tilt) const {
  const std::size_t n = s.bodies.size();
  const double steep = std::cos(std::atan(options_.friction) - tilt * M_PI / 180);
  std::vector<int> under(n, -3);  // what each body bears on; -3: nothing yet
  std::vector<std::vector<Vec3>> bearing(n);
  for (const auto& c : s.contacts) {
    // Seen from the body pushed: `c.on` bears on `c.from` where the normal faces up.
    for (const auto& [body, other, normal] : {std::tuple{c.on, c.from, c.normal}, std::tuple{c.from, c.on, Vec3(-c.normal)}}) {
      if (body < 0 || normal.y() < kBears) continue;
      if (normal.y() < steep) return false;  // bears, but too steep for the friction asked
      int& u = under[static_cast<std::size_t>(body)];
      const int on = other < 0 ? -1 : other;
      if (u != -3 && u != on) return false;  // bears on two things: a linear program's work
      u = on;
      bearing[static_cast<std::size_t>(body)].push_back(c.point);
    }
  }
  // Each body's load: itself and all that rests on it, in order from the top down.
  std::vector<double> load = s.mass;
  std::vector<Vec3> moment(n);
  for (std::size_t b = 0; b < n; ++b) moment[b] = s.mass[b] * s.centre[b];
  std::vector<int> rests(n, 0);
  for (std::size_t b = 0; b < n; ++b) {
    if (under[b] == -3) return false;  // bears on nothing
    if (under[b] >= 0) ++rests[static_cast<std::size_t>(under[b])];
  }
  std::vector<std::size_t> order;
  for (std::size_t b = 0; b < n; ++b) {
    if (rests[b] == 0) order.push_back(b);
  }
  for (std::size_t k = 0; k < order.size(); ++k) {
    const int u = under[order[k]];
    if (u < 0) continue;
    load[u] += load[order[k]];
    moment[u] += moment[order[k]];
    if (--rests[static_cast<std::size_t>(u)] == 0) order.push_back(static_cast<std::size_t>(u));
  }
  if (order.size() != n) return false;  // a cycle of bearing
  for (const Vec3& g : gravities(tilt, options_.tilt_directions)) {
    // Project along g onto the plane y = 0.
    const auto flat = [&](const Vec3& p) { return Eigen::Vector2d(p.x() - g.x() * p.y() / g.y(), p.z() - g.z() * p.y() / g.y()); };
    for (std::size_t b = 0; b < n; ++b) {
      std::vector<Eigen::Vector2d> points;
      for (const Vec3& p : bearing[b]) points.push_back(flat(p));
      if (!inside_hull(points, flat(moment[b] / load[b]))) return false;
    }
  }
  return true;
}

// Whether contact forces hold every body, under each gravity; what `assumed` parts bear.
StabilityAnalysis::Equilibrium StabilityAnalysis::solve(const State& s, double tilt) const {
  Equilibrium out;
  const std::size_t bodies = s.bodies.size();
  // Columns: a bearing contact's friction pyramid (four edges), a steep contact's normal.
  struct Push {
    int on, from;
    Vec3 point, direction;
  };
  std::vector<Push> pushes;
  for (const auto& c : s.contacts) {
    if (std::abs(c.normal.y()) < kBears) {
      pushes.push_back({c.on, c.from, c.point, c.normal});
      continue;
    }
    const Vec3 t1 = c.normal.unitOrthogonal(), t2 = c.normal.cross(t1);
    for (int j = 0; j < kPyramidEdges; ++j) {
      const double angle = 2 * M_PI * j / kPyramidEdges;
      pushes.push_back({c.on, c.from, c.point, c.normal + options_.friction * (std::cos(angle) * t1 + std::sin(angle) * t2)});
    }
  }
  // Rows: per body, force (3) and moment about its centre (3). Gravity on the right. The cost
  // is what assumed parts bear (the rest is free).
  const int rows = static_cast<int>(6 * bodies);
  std::vector<int> starts{0}, index;
  std::vector<double> value, cost;
  for (const Push& p : pushes) {
    for (const auto& [body, sign] : {std::pair{p.on, 1.0}, std::pair{p.from, -1.0}}) {
      if (body < 0) continue;
      const Vec3 f = sign * p.direction;
      const Vec3 m = ((p.point - s.centre[static_cast<std::size_t>(body)]) * kCm).cross(f);
      for (int k = 0; k < 3; ++k) {
        index.push_back(6 * body + k);
        value.push_back(f[k]);
        index.push_back(6 * body + 3 + k);
        value.push_back(m[k]);
      }
    }
    starts.push_back(static_cast<int>(index.size()));
    cost.push_back(p.on == -2 || p.from == -2 ? 1 : 0);
  }
  const int columns = static_cast<int>(pushes.size());
  if (columns == 0) {
    out.holds = false;
    return out;
  }
  const CoinPackedMatrix matrix(true, rows, columns, static_cast<CoinBigIndex>(value.size()), value.data(), index.data(),
                                starts.data(), nullptr);
  std::vector<double> lower(columns, 0), upper(columns, COIN_DBL_MAX), rhs(rows, 0);
  ClpSimplex lp;
  lp.setLogLevel(0);
  lp.loadProblem(matrix, lower.data(), upper.data(), cost.data(), rhs.data(), rhs.data());
  bool first = true;
  for (const Vec3& g : gravities(tilt, options_.tilt_directions)) {
    for (std::size_t b = 0; b < bodies; ++b) {
      for (int k = 0; k < 3; ++k) {
        const int row = static_cast<int>(6 * b) + k;
        const double weight = -s.mass[b] * kCm * kCm * kCm * g[k];
        lp.setRowLower(row, weight);
        lp.setRowUpper(row, weight);
      }
    }
    // Clp keeps its work areas and factorization between the solves (startFinishOptions
    // 1|2|4): only the right-hand side changes, and setting up took longer than solving.
    if (first) {
      lp.primal(0, 1);
    } else {
      lp.dual(0, 7);
    }
    first = false;
    if (!lp.isProvenOptimal()) {
      out.holds = false;
      return out;
    }
    out.load_on_assumed = std::max(out.load_on_assumed, lp.objectiveValue());
  }
  return out;
}

std::optional<Instability> StabilityAnalysis::check(const std::vector<PlacedPart>& placed,
                                                    const std::vector<PartIndex>& fixed,
                                                    const std::vector<bool>& fastened,
                                                    std::optional<PartIndex> added) const {
  // A state asked before is answered as before (the search and the replay ask the same ones).
  std::vector<double> key;
  for (const auto& p : placed) {
    key.push_back(static_cast<double>(p.part));
    const auto pose = key_of(p.pose);
    key.insert(key.end(), pose.begin(), pose.end());
  }
  key.push_back(-1);
  for (PartIndex f : fixed) key.push_back(static_cast<double>(f));
  key.push_back(-1);
  for (bool f : fastened) key.push_back(f ? 1 : 0);
  if (const auto known = impl_->answers.find(key); known != impl_->answers.end()) return known->second;
  return impl_->answers[key] = assess(placed, fixed, fastened, added);
}

std::optional<Instability> StabilityAnalysis::assess(const std::vector<PlacedPart>& placed,
                                                     const std::vector<PartIndex>& fixed,
                                                     const std::vector<bool>& fastened,
                                                     std::optional<PartIndex> added) const {
  const double margin = options_.tilt_margin;
  const State whole = state(placed, fixed, {}, fastened);
  if (whole.bodies.empty() || stacked(whole, margin)) return std::nullopt;
  const auto all_but = [&](const std::vector<PartIndex>& group) {
    std::vector<PartIndex> others;
    for (const auto& p : placed) {
      if (std::find(group.begin(), group.end(), p.part) == group.end()) others.push_back(p.part);
    }
    return others;
  };
  // How badly a group fails, the others standing still: not even upright, or at the margin.
  const auto failed = [&](const std::vector<PartIndex>& group) {
    const bool upright = solve(state(placed, fixed, all_but(group), fastened), 0).holds;
    return Instability{group, upright ? margin : 0};
  };
  if (added) {
    // The state before stood. The new part's group alone, the others standing still: if it
    // cannot be held, it moves; if it is held without leaning on them, nothing else changed.
    const State alone = state(placed, fixed, all_but({*added}), fastened);
    if (!alone.bodies.empty()) {
      const auto& group = alone.bodies.front();
      const State mine = state(placed, fixed, all_but(group), fastened);
      const Equilibrium e = solve(mine, margin);
      if (!e.holds) return failed(group);
      if (e.load_on_assumed <= 1e-9) return std::nullopt;
    }
  }
  if (solve(whole, margin).holds) return std::nullopt;
  // Which group moves: the first that cannot be held on its own, the others standing still.
  for (const auto& group : whole.bodies) {
    if (whole.bodies.size() > 1 && solve(state(placed, fixed, all_but(group), fastened), margin).holds) continue;
    return failed(group);
  }
  std::vector<PartIndex> all;
  for (const auto& b : whole.bodies) all.insert(all.end(), b.begin(), b.end());
  return Instability{all, solve(whole, 0).holds ? margin : 0};
}

std::string describe(const Product& product, const Instability& instability, const StabilityOptions& options) {
  std::string names;
  for (PartIndex p : instability.parts) names += (names.empty() ? "" : ", ") + product.parts()[p].name;
  char why[160];
  if (instability.tilt == 0) {
    std::snprintf(why, sizeof why, "nothing holds it up: it would fall or topple");
  } else {
    std::snprintf(why, sizeof why, "it would topple or slide with gravity tilted %.0f degrees (the margin asked)",
                  options.tilt_margin);
  }
  return names + (instability.parts.size() == 1 ? ": " : " (together): ") + why;
}

}  // namespace twin
