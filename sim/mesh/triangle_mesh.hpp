#pragma once
// A part's geometry as read from its mesh file, in the part's own frame, in metres.

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

namespace sim {

struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  // The file's objects (OBJ "o"/"g" groups, COLLADA geometries), each a list of vertex
  // indices. A mesh authored as a convex decomposition has one convex object per piece.
  std::vector<std::vector<std::uint32_t>> pieces;
  // Per piece, the vertices on its convex hull (a subset of the piece's): the collision hulls
  // are made of these, whose support queries then skip a bore's or a stud's inner vertices.
  // Empty when not computed (a mesh made in code): the hulls take every vertex.
  std::vector<std::vector<std::uint32_t>> hull_corners;
  // A one-piece mesh of many hull corners has a coarse hull too: a few of them (kCoarseCorners
  // at most, spread by farthest-point sampling), grown by `coarse_margin` (m) so that it holds
  // every vertex. A concave mesh is checked by it first and by its triangles only where it
  // penetrates; a convex mesh is checked by it alone where it is at most kSimplifiedHullGrowth
  // larger than the hull (a pin of 50 000 triangles: each GJK support then looks at 256
  // corners, not 25 000), and has none otherwise. Empty where the hull has few corners: then
  // it is the hull itself.
  std::vector<std::uint32_t> coarse_corners;
  double coarse_margin = 0;
  Eigen::AlignedBox3d bounds;
  // One closed piece whose surface is its convex hull (a box, a pin): its hull is exact.
  // False for anything concave, open or inconsistently wound, which is the safe side.
  bool convex = false;
  // A concave one-piece mesh's triangle tree, as Bullet checks a static one: its nodes, made
  // at loading and kept in the disk cache (sim/mesh/triangle_bvh.hpp). Empty for other meshes,
  // and for one made in code: the collision world then builds the tree.
  std::vector<std::uint8_t> bvh_nodes;

  // What loading found and repaired (a CAD export is rarely clean). Degenerate triangles
  // (a repeated corner, or no area) and duplicates (the same three corners) are dropped;
  // triangles wound against their neighbours, or a closed piece wound inside out, are turned
  // to face outwards (flipped); an open edge that other open edges' corners lie on is split
  // there (t_junctions: the surface is the same, and closed); a hole of three open edges is
  // closed by the triangle missing there (missing_triangles); edges with one triangle (open)
  // or more than two (non-manifold) are counted.
  // A file's objects are taken as the convex pieces of a decomposition only where every one
  // of them closes a convex solid; where not (a CAD export that writes a face or a body per
  // object), the objects are joined into one piece, welded where their corners coincide, and
  // `joined_objects` says how many there were.
  struct Repairs {
    std::size_t degenerate = 0, duplicate = 0, flipped = 0, t_junctions = 0, missing_triangles = 0, open_edges = 0;
    std::size_t non_manifold_edges = 0, joined_objects = 0;
    bool any() const {
      return degenerate + duplicate + flipped + t_junctions + missing_triangles + open_edges + non_manifold_edges +
             joined_objects > 0;
    }
    std::string describe() const;  // "dropped 3 degenerate triangles; 12 open edges", or ""
  } repairs;
};

// Whether the mesh is one closed convex piece: its volume is its hull's (to 0.1 %).
bool is_convex(const TriangleMesh& mesh);
// Whether the hulls of its pieces are the mesh (authored as convex pieces, or one convex
// piece); otherwise it is one piece that may be concave, whose triangles are its shape.
inline bool pieces_are_exact(const TriangleMesh& mesh) { return mesh.pieces.size() > 1 || mesh.convex; }
// Each piece's vertices on its convex hull (all of them for a flat or degenerate piece).
std::vector<std::vector<std::uint32_t>> hull_corners(const TriangleMesh& mesh);
constexpr std::size_t kCoarseCorners = 256;
// 0.01 mm: a thirtieth of the contact tolerance, and on the safe side (the hull only grows,
// and a distance to it is taken to its grown surface).
constexpr double kSimplifiedHullGrowth = 1e-5;
// Fills coarse_corners and coarse_margin of a one-piece mesh whose hull_corners are set.
void make_coarse_hull(TriangleMesh& mesh);
// How far the farthest of `points` lies outside the convex hull of `hull_of` (vertex indices
// of the mesh), m; 0 where all lie inside it.
double farthest_outside(const TriangleMesh& mesh, const std::vector<std::uint32_t>& hull_of,
                        const std::vector<std::uint32_t>& points);
// Whether the collision check takes a convex mesh's hull as its coarse one (make_coarse_hull).
inline bool hull_simplified(const TriangleMesh& mesh) { return mesh.convex && !mesh.coarse_corners.empty(); }
// What loading repaired or found, and what the check simplifies, for a finding ("" for none).
std::string loading_report(const TriangleMesh& mesh);

class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads OBJ, STL, COLLADA, PLY, glTF and the rest of what Assimp reads, its coordinates
// times `scale` (metres per unit of the file: 0.001 for a CAD export in millimetres).
// Throws MeshError when the file cannot be read or holds no triangles.
std::shared_ptr<const TriangleMesh> load_mesh(const std::filesystem::path& file, double scale = 1);

class MeshDiskCache;

// Each file read once, shared by every part that uses it; read through the disk cache
// (mesh_disk_cache.hpp) that the environment names, or the one given (none: off).
class MeshCache {
 public:
  MeshCache();
  explicit MeshCache(const std::optional<std::filesystem::path>& disk_folder);
  std::shared_ptr<const TriangleMesh> get(const std::filesystem::path& file, double scale = 1);
  std::size_t size() const { return meshes_.size(); }

 private:
  std::shared_ptr<MeshDiskCache> disk_;
  std::unordered_map<std::string, std::shared_ptr<const TriangleMesh>> meshes_;
};

}  // namespace sim
