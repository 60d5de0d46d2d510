#pragma once
// The shape of a static concave one-piece mesh as Bullet checks it: its triangles in
// Bullet's units and their bounding-volume tree (btBvhTriangleMeshShape). The tree is built
// once, when the mesh is loaded, and kept with the mesh in the disk cache: building it was a
// quarter of a plan of twenty 50 000-triangle parts read from the cache.

#include <cstdint>
#include <memory>
#include <vector>

#include "sim/mesh/triangle_mesh.hpp"

class btOptimizedBvh;
class btTriangleIndexVertexArray;
class btBvhTriangleMeshShape;

namespace sim {

// Bullet works in millimetres: its tolerances are meant for objects of that size.
constexpr double kBulletUnitsPerMetre = 1000.0;

// The nodes of the mesh's tree (Bullet's quantized nodes, 16 bytes each), as
// TriangleMesh::bvh_nodes keeps them.
std::vector<std::uint8_t> triangle_bvh_nodes(const TriangleMesh& mesh);

// The mesh's triangles and their tree: the tree from `mesh.bvh_nodes` where they are a whole
// tree of these triangles, built anew otherwise (a mesh made in code, a damaged cache entry).
class StaticMeshShape {
 public:
  StaticMeshShape(const TriangleMesh& mesh, double margin);
  ~StaticMeshShape();
  StaticMeshShape(const StaticMeshShape&) = delete;
  StaticMeshShape& operator=(const StaticMeshShape&) = delete;

  btBvhTriangleMeshShape& shape() { return *shape_; }
  bool tree_was_kept() const { return kept_; }

 private:
  std::vector<float> vertices_;
  std::vector<int> indices_;
  std::unique_ptr<btTriangleIndexVertexArray> array_;
  std::unique_ptr<btOptimizedBvh> tree_;
  std::unique_ptr<btBvhTriangleMeshShape> shape_;
  bool kept_ = false;
};

}  // namespace sim
