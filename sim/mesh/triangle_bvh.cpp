#include "sim/mesh/triangle_bvh.hpp"

#include <cstring>

#include <btBulletCollisionCommon.h>

namespace sim {
namespace {

// Bullet's tree, with its nodes written out and read back. Bullet reads only the nodes (the
// stackless traversal, btQuantizedBvh's default, uses neither subtree headers nor leaf lists);
// the quantization is set from the shape's box as btOptimizedBvh::build sets it.
class Tree : public btOptimizedBvh {
 public:
  std::vector<std::uint8_t> nodes() const {
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m_curNodeIndex) * sizeof(btQuantizedBvhNode));
    if (!bytes.empty()) std::memcpy(bytes.data(), &m_quantizedContiguousNodes[0], bytes.size());
    return bytes;
  }

  // False, and nothing taken, unless the nodes are a whole tree over `triangles` triangles:
  // one leaf per triangle of part 0, and every skip within the tree.
  bool take(const std::vector<std::uint8_t>& bytes, int triangles, const btVector3& min, const btVector3& max) {
    const std::size_t count = bytes.size() / sizeof(btQuantizedBvhNode);
    if (triangles < 1 || bytes.size() % sizeof(btQuantizedBvhNode) != 0 ||
        count != 2 * static_cast<std::size_t>(triangles) - 1) {
      return false;
    }
    const int size = static_cast<int>(count);
    for (int i = 0; i < size; ++i) {
      btQuantizedBvhNode node;
      std::memcpy(&node, bytes.data() + i * sizeof node, sizeof node);
      const std::int64_t v = node.m_escapeIndexOrTriangleIndex;  // a skip is negative (INT_MIN too)
      const bool whole = v >= 0 ? node.getPartId() == 0 && node.getTriangleIndex() < triangles : i - v <= size;
      if (!whole) return false;
    }
    m_useQuantization = true;
    setQuantizationValues(min, max);
    m_quantizedContiguousNodes.resize(size);
    std::memcpy(&m_quantizedContiguousNodes[0], bytes.data(), bytes.size());
    m_curNodeIndex = size;
    m_traversalMode = TRAVERSAL_STACKLESS;
    return true;
  }
};

struct Arrays {
  std::vector<float> vertices;
  std::vector<int> indices;
};

Arrays bullet_arrays(const TriangleMesh& mesh) {
  Arrays a;
  a.vertices.reserve(3 * mesh.vertices.size());
  for (const auto& v : mesh.vertices) {
    for (int k = 0; k < 3; ++k) a.vertices.push_back(static_cast<float>(v[k] * kBulletUnitsPerMetre));
  }
  a.indices.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles) a.indices.insert(a.indices.end(), {int(t[0]), int(t[1]), int(t[2])});
  return a;
}

// With the box of the triangles' corners given: the shape would find it by six passes of a
// support query over every triangle, each time a world takes the mesh.
std::unique_ptr<btTriangleIndexVertexArray> index_array(std::vector<float>& vertices, std::vector<int>& indices) {
  auto array = std::make_unique<btTriangleIndexVertexArray>(static_cast<int>(indices.size() / 3), indices.data(),
                                                            3 * sizeof(int), static_cast<int>(vertices.size() / 3),
                                                            vertices.data(), 3 * sizeof(float));
  btVector3 min(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT), max = -min;
  for (int i : indices) {
    const btVector3 v(vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2]);
    min.setMin(v);
    max.setMax(v);
  }
  array->setPremadeAabb(min, max);
  return array;
}

}  // namespace

std::vector<std::uint8_t> triangle_bvh_nodes(const TriangleMesh& mesh) {
  Arrays a = bullet_arrays(mesh);
  const auto array = index_array(a.vertices, a.indices);
  const btBvhTriangleMeshShape shape(array.get(), true, false);  // its box, as buildOptimizedBvh uses it
  Tree tree;
  tree.build(array.get(), true, shape.getLocalAabbMin(), shape.getLocalAabbMax());
  return tree.nodes();
}

StaticMeshShape::StaticMeshShape(const TriangleMesh& mesh, double margin) {
  Arrays a = bullet_arrays(mesh);
  vertices_ = std::move(a.vertices);
  indices_ = std::move(a.indices);
  array_ = index_array(vertices_, indices_);
  shape_ = std::make_unique<btBvhTriangleMeshShape>(array_.get(), true, false);
  auto kept = std::make_unique<Tree>();
  kept_ = kept->take(mesh.bvh_nodes, static_cast<int>(mesh.triangles.size()), shape_->getLocalAabbMin(),
                     shape_->getLocalAabbMax());
  if (kept_) {
    tree_ = std::move(kept);
    shape_->setOptimizedBvh(tree_.get());
  } else {
    shape_->buildOptimizedBvh();
  }
  shape_->setMargin(static_cast<btScalar>(margin * kBulletUnitsPerMetre));
}

StaticMeshShape::~StaticMeshShape() = default;

}  // namespace sim
