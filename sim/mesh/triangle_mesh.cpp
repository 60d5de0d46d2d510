#include "sim/mesh/triangle_mesh.hpp"

#include "sim/mesh/mesh_disk_cache.hpp"
#include "sim/mesh/mesh_import.hpp"
#include "sim/mesh/triangle_bvh.hpp"

#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <LinearMath/btConvexHullComputer.h>

#include <algorithm>
#include <limits>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

namespace sim {
namespace {

using EdgeUsers = std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::size_t>>;  // undirected edge -> triangles

bool has_edge(const std::array<std::uint32_t, 3>& t, std::uint32_t a, std::uint32_t b) {
  for (int k = 0; k < 3; ++k) {
    if (t[k] == a && t[(k + 1) % 3] == b) return true;
  }
  return false;
}

// Winds each connected piece one way, outwards (a CAD export may flip some normals): a
// triangle wound like its neighbour across a shared edge is turned over, and a closed piece
// whose volume comes out negative is turned inside out. Counts the triangles turned.
void orient(TriangleMesh& mesh, const EdgeUsers& edges) {
  auto& tris = mesh.triangles;
  std::vector<bool> seen(tris.size(), false), turned(tris.size(), false);
  const auto turn = [&](std::size_t i) {
    std::swap(tris[i][1], tris[i][2]);
    turned[i] = !turned[i];
  };
  for (std::size_t seed = 0; seed < tris.size(); ++seed) {
    if (seen[seed]) continue;
    std::vector<std::size_t> piece{seed};
    seen[seed] = true;
    bool closed = true;
    for (std::size_t next = 0; next < piece.size(); ++next) {
      const auto t = tris[piece[next]];
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = t[k], b = t[(k + 1) % 3];
        const auto& users = edges.at(std::minmax(a, b));
        if (users.size() != 2) {
          closed = false;
          continue;  // open or non-manifold: no neighbour to agree with
        }
        const std::size_t n = users[0] == piece[next] ? users[1] : users[0];
        if (seen[n]) continue;
        if (has_edge(tris[n], a, b)) turn(n);  // runs the shared edge the same way: turned over
        seen[n] = true;
        piece.push_back(n);
      }
    }
    double volume = 0;
    for (std::size_t i : piece) {
      const auto& t = tris[i];
      volume += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
    }
    if (closed && volume < 0) {
      for (std::size_t i : piece) turn(i);
    }
  }
  mesh.repairs.flipped = static_cast<std::size_t>(std::count(turned.begin(), turned.end(), true));
}

// Whether every piece closes a convex solid of its own (a decomposition authored as such).
bool convex_pieces(const TriangleMesh& mesh) {
  std::vector<std::size_t> piece_of(mesh.vertices.size(), 0);
  std::vector<std::vector<std::uint32_t>> index(mesh.pieces.size());  // each piece's vertices, sorted
  std::vector<TriangleMesh> own(mesh.pieces.size());
  for (std::size_t p = 0; p < mesh.pieces.size(); ++p) {
    index[p] = mesh.pieces[p];
    std::sort(index[p].begin(), index[p].end());
    own[p].pieces.emplace_back();
    for (auto v : index[p]) {
      piece_of[v] = p;
      own[p].pieces.back().push_back(static_cast<std::uint32_t>(own[p].vertices.size()));
      own[p].vertices.push_back(mesh.vertices[v]);
    }
  }
  const auto local = [&](std::size_t p, std::uint32_t v) {
    return static_cast<std::uint32_t>(std::lower_bound(index[p].begin(), index[p].end(), v) - index[p].begin());
  };
  for (const auto& t : mesh.triangles) {
    const std::size_t p = piece_of[t[0]];
    if (piece_of[t[1]] != p || piece_of[t[2]] != p) return false;  // a triangle across objects
    own[p].triangles.push_back({local(p, t[0]), local(p, t[1]), local(p, t[2])});
  }
  for (const TriangleMesh& piece : own) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
    for (const auto& t : piece.triangles) {
      for (int k = 0; k < 3; ++k) ++uses[std::minmax(t[k], t[(k + 1) % 3])];
    }
    if (uses.empty() || std::any_of(uses.begin(), uses.end(), [](const auto& u) { return u.second != 2; })) return false;
    if (!is_convex(piece)) return false;
  }
  return true;
}

// One piece of all the objects, their corners welded where they coincide.
void join_pieces(TriangleMesh& mesh) {
  std::map<std::array<double, 3>, std::uint32_t> first;
  std::vector<std::uint32_t> to(mesh.vertices.size());
  std::vector<Eigen::Vector3d> kept;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Eigen::Vector3d& p = mesh.vertices[v];
    const auto [it, fresh] = first.try_emplace({p.x(), p.y(), p.z()}, static_cast<std::uint32_t>(kept.size()));
    if (fresh) kept.push_back(p);
    to[v] = it->second;
  }
  for (auto& t : mesh.triangles) t = {to[t[0]], to[t[1]], to[t[2]]};
  mesh.repairs.joined_objects = mesh.pieces.size();
  mesh.vertices = std::move(kept);
  mesh.pieces.assign(1, {});
  for (std::uint32_t v = 0; v < mesh.vertices.size(); ++v) mesh.pieces.front().push_back(v);
}

EdgeUsers edge_users(const TriangleMesh& mesh) {
  EdgeUsers edges;
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    for (int k = 0; k < 3; ++k) edges[std::minmax(t[k], t[(k + 1) % 3])].push_back(i);
  }
  return edges;
}

// Splits each open edge at the corners of other open edges that lie on it. A CAD export that
// meshes two faces apart may run one face's edge whole past a corner where the other face's
// edge is split (a T-junction): the mesh looks open where it is closed (a pulley: 3 open
// edges, so no inside to measure an overlap by). The surface stays as it was. Returns how many
// edges were split.
std::size_t split_at_t_junctions(TriangleMesh& mesh, const EdgeUsers& edges) {
  std::vector<std::uint32_t> loose;  // the corners of open edges, by x
  for (const auto& [edge, users] : edges) {
    if (users.size() != 1) continue;
    loose.push_back(edge.first);
    loose.push_back(edge.second);
  }
  if (loose.empty()) return 0;
  const auto x_of = [&](std::uint32_t v) { return mesh.vertices[v].x(); };
  std::sort(loose.begin(), loose.end());
  loose.erase(std::unique(loose.begin(), loose.end()), loose.end());
  std::sort(loose.begin(), loose.end(), [&](std::uint32_t u, std::uint32_t v) { return x_of(u) < x_of(v); });

  std::vector<bool> replaced(mesh.triangles.size(), false);
  std::vector<std::array<std::uint32_t, 3>> added;
  std::size_t split = 0;
  // Corners looked at, at most: a hostile file whose open corners share one x would otherwise
  // cost their number squared. What is left unsplit stays open, and is said to be.
  std::size_t budget = 64 * loose.size() + 1'000'000;
  for (const auto& [edge, users] : edges) {
    if (budget == 0) break;
    if (users.size() != 1 || replaced[users[0]]) continue;
    const auto& t = mesh.triangles[users[0]];
    int k = 0;
    while (std::pair<std::uint32_t, std::uint32_t>(std::minmax(t[k], t[(k + 1) % 3])) != edge) ++k;
    const std::uint32_t a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
    const Eigen::Vector3d &pa = mesh.vertices[a], &pb = mesh.vertices[b];
    const Eigen::Vector3d ab = pb - pa;
    const double length2 = ab.squaredNorm();
    const double tolerance = 1e-6 * std::sqrt(length2);  // a float's rounding of CAD coordinates, with room
    const auto first = std::lower_bound(loose.begin(), loose.end(), std::min(pa.x(), pb.x()) - tolerance,
                                        [&](std::uint32_t v, double x) { return x_of(v) < x; });
    std::vector<std::pair<double, std::uint32_t>> on;  // corners on the edge, by their place along it
    for (auto it = first; it != loose.end() && x_of(*it) <= std::max(pa.x(), pb.x()) + tolerance && budget > 0;
         ++it, --budget) {
      const Eigen::Vector3d& p = mesh.vertices[*it];
      const double along = (p - pa).dot(ab) / length2;
      if (along <= 1e-6 || along >= 1 - 1e-6 || (pa + along * ab - p).norm() > tolerance) continue;
      on.emplace_back(along, *it);
    }
    if (on.empty()) continue;
    std::sort(on.begin(), on.end());
    replaced[users[0]] = true;
    ++split;
    std::uint32_t from = a;  // a fan from c, wound as the triangle was
    for (const auto& [along, v] : on) {
      added.push_back({from, v, c});
      from = v;
    }
    added.push_back({from, b, c});
  }
  if (split == 0) return 0;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    if (!replaced[i]) mesh.triangles[kept++] = mesh.triangles[i];
  }
  mesh.triangles.resize(kept);
  mesh.triangles.insert(mesh.triangles.end(), added.begin(), added.end());
  return split;
}

// Fills each hole of three open edges, of three triangles, with the triangle that is missing
// (a CAD export that dropped one): the only surface that closes it. Holes of more edges are
// left open (two rims of a bore whose wall is missing would be closed wrongly by two caps).
// Returns how many were filled.
std::size_t fill_missing_triangles(TriangleMesh& mesh, const EdgeUsers& edges) {
  // Each open edge as its triangle runs it, by the corner it leaves.
  std::multimap<std::uint32_t, std::pair<std::uint32_t, std::size_t>> out;  // from -> (to, triangle)
  for (const auto& [edge, users] : edges) {
    if (users.size() != 1) continue;
    const auto& t = mesh.triangles[users[0]];
    const bool forward = has_edge(t, edge.first, edge.second);
    out.emplace(forward ? edge.first : edge.second, std::pair{forward ? edge.second : edge.first, users[0]});
  }
  std::set<std::pair<std::uint32_t, std::uint32_t>> filled;  // undirected edges closed
  std::size_t count = 0;
  std::size_t budget = 64 * out.size() + 1'000'000;  // pairs of edges looked at (a hostile fan)
  for (const auto& entry : out) {
    const std::uint32_t a = entry.first, b = entry.second.first;
    const std::size_t t_ab = entry.second.second;
    const auto [first, last] = out.equal_range(b);
    for (auto bc = first; bc != last && budget > 0; ++bc, --budget) {
      const std::uint32_t c = bc->second.first;
      const std::size_t t_bc = bc->second.second;
      const auto [from_c, end_c] = out.equal_range(c);
      const bool closes = std::any_of(from_c, end_c, [&](const auto& ca) {
        return ca.second.first == a && ca.second.second != t_ab && ca.second.second != t_bc;
      });
      if (!closes || t_ab == t_bc || filled.count(std::minmax(a, b)) || filled.count(std::minmax(b, c)) ||
          filled.count(std::minmax(c, a))) {
        continue;
      }
      const Eigen::Vector3d &pa = mesh.vertices[a], &pb = mesh.vertices[b], &pc = mesh.vertices[c];
      if ((pb - pa).cross(pc - pa).squaredNorm() <= 1e-24 * std::pow((pb - pa).squaredNorm() + (pc - pa).squaredNorm(), 2)) {
        continue;  // no area: nothing to fill
      }
      mesh.triangles.push_back({a, c, b});  // against the way its neighbours run the edges
      filled.insert(std::minmax(a, b));
      filled.insert(std::minmax(b, c));
      filled.insert(std::minmax(c, a));
      ++count;
      break;
    }
  }
  return count;
}

// Drops degenerate and duplicate triangles; splits edges at T-junctions; fills missing
// triangles; counts open and non-manifold edges; winds the triangles outwards.
void repair(TriangleMesh& mesh) {
  using Corners = std::array<std::uint32_t, 3>;
  std::set<Corners> seen;
  std::vector<Corners> kept;
  kept.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    const double scale = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || (b - a).cross(c - a).squaredNorm() <= 1e-24 * scale * scale) {
      ++mesh.repairs.degenerate;
      continue;
    }
    Corners sorted = t;
    std::sort(sorted.begin(), sorted.end());
    if (!seen.insert(sorted).second) {
      ++mesh.repairs.duplicate;
      continue;
    }
    kept.push_back(t);
  }
  mesh.triangles = std::move(kept);
  EdgeUsers edges = edge_users(mesh);
  mesh.repairs.t_junctions = split_at_t_junctions(mesh, edges);
  if (mesh.repairs.t_junctions > 0) edges = edge_users(mesh);
  mesh.repairs.missing_triangles = fill_missing_triangles(mesh, edges);
  if (mesh.repairs.missing_triangles > 0) edges = edge_users(mesh);
  for (const auto& [edge, users] : edges) {
    if (users.size() == 1) ++mesh.repairs.open_edges;
    if (users.size() > 2) ++mesh.repairs.non_manifold_edges;
  }
  orient(mesh, edges);
}

// The closest point of the triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                    const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denominator = 1 / (va + vb + vc);
  return a + ab * (vb * denominator) + ac * (vc * denominator);
}

}  // namespace

double farthest_outside(const TriangleMesh& mesh, const std::vector<std::uint32_t>& hull_of,
                        const std::vector<std::uint32_t>& points) {
  std::vector<Eigen::Vector3d> taken;
  for (auto index : hull_of) taken.push_back(mesh.vertices[index]);
  btConvexHullComputer hull;
  hull.compute(taken.front().data(), sizeof(Eigen::Vector3d), static_cast<int>(taken.size()), 0, 0);
  // Its faces as triangle fans of the taken points (exact, in doubles), with outward normals.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : taken) centre += p;
  centre /= static_cast<double>(taken.size());
  struct Face {
    std::vector<Eigen::Vector3d> corners;
    Eigen::Vector3d normal;
    double offset;
  };
  std::vector<Face> faces;
  for (int f = 0; f < hull.faces.size(); ++f) {
    Face face;
    const btConvexHullComputer::Edge* first = &hull.edges[hull.faces[f]];
    const btConvexHullComputer::Edge* e = first;
    do {
      face.corners.push_back(taken[static_cast<std::size_t>(hull.original_vertex_index[e->getSourceVertex()])]);
      e = e->getNextEdgeOfFace();
    } while (e != first && face.corners.size() <= taken.size());
    if (face.corners.size() < 3) continue;
    Eigen::Vector3d n = Eigen::Vector3d::Zero();  // Newell's normal of the polygon
    for (std::size_t i = 0; i < face.corners.size(); ++i) n += face.corners[i].cross(face.corners[(i + 1) % face.corners.size()]);
    if (n.norm() == 0) continue;
    n.normalize();
    if (n.dot(face.corners[0] - centre) < 0) n = -n;
    face.normal = n;
    face.offset = n.dot(face.corners[0]);
    faces.push_back(std::move(face));
  }
  double farthest = 0;
  constexpr double kOnPlane = 1e-10;  // m: rounding of a corner that lies on a face
  for (auto index : points) {
    const Eigen::Vector3d& p = mesh.vertices[index];
    // Outside a convex hull, the nearest point lies on a face the point sees; a corner of the
    // hull lies on its own faces (to rounding), and is 0 from them.
    double nearest = std::numeric_limits<double>::infinity();
    bool sees_one = false;
    for (const Face& face : faces) {
      const double above = face.normal.dot(p) - face.offset;
      if (above < -kOnPlane) continue;
      sees_one = sees_one || above > kOnPlane;
      for (std::size_t i = 1; i + 1 < face.corners.size(); ++i) {
        nearest = std::min(nearest, (p - closest_on_triangle(p, face.corners[0], face.corners[i], face.corners[i + 1])).norm());
      }
    }
    if (sees_one) farthest = std::max(farthest, nearest);
  }
  return farthest;
}

std::string TriangleMesh::Repairs::describe() const {
  std::vector<std::string> said;
  if (joined_objects > 0) {
    said.push_back(std::to_string(joined_objects) + " objects that are not convex pieces joined into one");
  }
  const auto say = [&](std::size_t n, const std::string& one, const std::string& many) {
    if (n > 0) said.push_back(std::to_string(n) + " " + (n == 1 ? one : many));
  };
  say(degenerate, "degenerate triangle dropped", "degenerate triangles dropped");
  say(duplicate, "duplicate triangle dropped", "duplicate triangles dropped");
  say(flipped, "triangle turned to face outwards (its normal was flipped)",
      "triangles turned to face outwards (their normals were flipped)");
  say(t_junctions, "edge split at a corner that lay on it (a T-junction)",
      "edges split at corners that lay on them (T-junctions)");
  say(missing_triangles, "missing triangle filled (a hole of three edges)", "missing triangles filled (holes of three edges)");
  say(open_edges, "open edge (the mesh is not closed)", "open edges (the mesh is not closed)");
  say(non_manifold_edges, "edge shared by more than two triangles", "edges shared by more than two triangles");
  std::string out;
  for (const auto& s : said) out += (out.empty() ? "" : "; ") + s;
  return out;
}

std::shared_ptr<const TriangleMesh> load_mesh(const std::filesystem::path& file, double scale) {
  auto mesh = std::make_shared<TriangleMesh>();
  import_mesh(file, *mesh);
  if (mesh->triangles.empty()) throw MeshError("mesh " + file.string() + " holds no triangles");
  if (mesh->pieces.size() > 1 && !convex_pieces(*mesh)) join_pieces(*mesh);
  if (scale != 1) {
    for (auto& v : mesh->vertices) v *= scale;
    mesh->bounds = Eigen::AlignedBox3d(mesh->bounds.min() * scale, mesh->bounds.max() * scale);
  }
  for (const auto& v : mesh->vertices) {
    if (!v.allFinite()) throw MeshError("mesh " + file.string() + " has a vertex that is not finite");
  }
  repair(*mesh);
  if (mesh->triangles.empty()) throw MeshError("mesh " + file.string() + " holds only degenerate triangles");
  mesh->convex = is_convex(*mesh);
  mesh->hull_corners = hull_corners(*mesh);
  make_coarse_hull(*mesh);
  if (!pieces_are_exact(*mesh)) mesh->bvh_nodes = triangle_bvh_nodes(*mesh);
  return mesh;
}

void make_coarse_hull(TriangleMesh& mesh) {
  mesh.coarse_corners.clear();
  mesh.coarse_margin = 0;
  if (mesh.pieces.size() != 1 || mesh.hull_corners.size() != 1) return;
  const auto& corners = mesh.hull_corners[0];
  if (corners.size() <= kCoarseCorners) return;
  // Farthest-point sampling: each next corner the one farthest from those taken.
  std::vector<double> nearest(corners.size(), std::numeric_limits<double>::infinity());
  std::size_t next = 0;
  for (std::size_t taken = 0; taken < kCoarseCorners; ++taken) {
    mesh.coarse_corners.push_back(corners[next]);
    const Eigen::Vector3d& p = mesh.vertices[corners[next]];
    std::size_t farthest = 0;
    for (std::size_t i = 0; i < corners.size(); ++i) {
      nearest[i] = std::min(nearest[i], (mesh.vertices[corners[i]] - p).squaredNorm());
      if (nearest[i] > nearest[farthest]) farthest = i;
    }
    next = farthest;
  }
  // How far the corners left out lie outside the hull of those taken. (Bullet's GJK, which
  // was asked this before, answers some corners of a CAD export's rounded edges with
  // infinity: the hull then grew by 3e35 m and every collision of the part went unseen.)
  const double outside = farthest_outside(mesh, mesh.coarse_corners, corners);
  // A little over, for the checks' own rounding.
  mesh.coarse_margin = outside * 1.01 + 1e-6;
  // A convex mesh too round for 256 corners (a sphere), or a hull that would not be near the
  // mesh (no such mesh is known; the full hull is then the coarse one): none.
  if ((mesh.convex && mesh.coarse_margin > kSimplifiedHullGrowth) || !(mesh.coarse_margin < 0.01 * mesh.bounds.sizes().norm())) {
    mesh.coarse_corners.clear();
    mesh.coarse_margin = 0;
  }
}

std::string loading_report(const TriangleMesh& mesh) {
  std::string out = mesh.repairs.describe();
  if (hull_simplified(mesh)) {
    char growth[32];
    std::snprintf(growth, sizeof growth, "%.4f", mesh.coarse_margin * 1000);
    out += (out.empty() ? "" : "; ") + std::string("its collision hull simplified from ") +
           std::to_string(mesh.hull_corners.front().size()) + " to " + std::to_string(mesh.coarse_corners.size()) +
           " corners, at most " + growth + " mm larger";
  }
  return out;
}

std::vector<std::vector<std::uint32_t>> hull_corners(const TriangleMesh& mesh) {
  std::vector<std::vector<std::uint32_t>> out;
  for (const auto& piece : mesh.pieces) {
    std::vector<Eigen::Vector3d> points;
    points.reserve(piece.size());
    for (auto index : piece) points.push_back(mesh.vertices[index]);
    btConvexHullComputer hull;
    if (!points.empty()) hull.compute(points.front().data(), sizeof(Eigen::Vector3d), static_cast<int>(points.size()), 0, 0);
    std::vector<std::uint32_t> corners;
    if (hull.vertices.size() >= 4) {
      for (int i = 0; i < hull.original_vertex_index.size(); ++i) corners.push_back(piece[hull.original_vertex_index[i]]);
    } else {
      corners = piece;
    }
    out.push_back(std::move(corners));
  }
  return out;
}

bool is_convex(const TriangleMesh& mesh) {
  if (mesh.pieces.size() != 1 || mesh.vertices.size() < 4) return false;
  const auto tetra = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    return a.dot(b.cross(c)) / 6;
  };
  double volume = 0;
  for (const auto& t : mesh.triangles) volume += tetra(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]);
  btConvexHullComputer hull;
  hull.compute(mesh.vertices.front().data(), sizeof(Eigen::Vector3d), static_cast<int>(mesh.vertices.size()), 0, 0);
  const auto vertex = [&](int i) {
    const btVector3& v = hull.vertices[i];
    return Eigen::Vector3d(v.x(), v.y(), v.z());
  };
  double hull_volume = 0;
  for (int f = 0; f < hull.faces.size(); ++f) {
    const btConvexHullComputer::Edge* first = &hull.edges[hull.faces[f]];
    const int a = first->getSourceVertex();
    for (auto* e = first->getNextEdgeOfFace(); e->getTargetVertex() != a; e = e->getNextEdgeOfFace()) {
      hull_volume += tetra(vertex(a), vertex(e->getSourceVertex()), vertex(e->getTargetVertex()));
    }
  }
  hull_volume = std::abs(hull_volume);
  return hull_volume > 0 && std::abs(volume) >= (1 - 1e-3) * hull_volume && std::abs(volume) <= (1 + 1e-3) * hull_volume;
}

MeshCache::MeshCache() : MeshCache(MeshDiskCache::folder_from_environment()) {}

MeshCache::MeshCache(const std::optional<std::filesystem::path>& disk_folder)
    : disk_(disk_folder ? std::make_shared<MeshDiskCache>(*disk_folder) : nullptr) {}

std::shared_ptr<const TriangleMesh> MeshCache::get(const std::filesystem::path& file, double scale) {
  const std::string key = file.string() + '@' + std::to_string(scale);
  if (auto it = meshes_.find(key); it != meshes_.end()) return it->second;
  auto mesh = disk_ ? disk_->load(file, scale) : load_mesh(file, scale);
  meshes_.emplace(key, mesh);
  return mesh;
}

}  // namespace sim
