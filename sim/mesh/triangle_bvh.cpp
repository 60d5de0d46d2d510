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

  // False, and nothing taken, unless the nodes are a whole tree of these triangles: every
  // internal node's skip is one more than its two subtrees, every triangle (of part 0) is one
  // leaf, and every box holds what lies under it (a leaf: its triangle, as quantized now). A
  // damaged cache entry, or one of another Bullet, is then refused, not trusted.
  bool take(const std::vector<std::uint8_t>& bytes, const std::vector<float>& vertices, const std::vector<int>& indices,
            const btVector3& min, const btVector3& max) {
    const int triangles = static_cast<int>(indices.size() / 3);
    const std::size_t count = bytes.size() / sizeof(btQuantizedBvhNode);
    if (triangles < 1 || bytes.size() % sizeof(btQuantizedBvhNode) != 0 ||
        count != 2 * static_cast<std::size_t>(triangles) - 1) {
      return false;
    }
    const int size = static_cast<int>(count);
    std::vector<btQuantizedBvhNode> nodes(count);
    std::memcpy(nodes.data(), bytes.data(), bytes.size());
    m_useQuantization = true;
    setQuantizationValues(min, max);  // as btOptimizedBvh::build does, from the same box
    const auto holds = [](const btQuantizedBvhNode& outer, const unsigned short* lo, const unsigned short* hi) {
      for (int k = 0; k < 3; ++k) {
        if (outer.m_quantizedAabbMin[k] > lo[k] || outer.m_quantizedAabbMax[k] < hi[k]) return false;
      }
      return true;
    };
    // A node's extent in the array: itself for a leaf, its skip for an internal node (a skip
    // is negative in the node, INT_MIN too; read as 64 bits).
    const auto extent = [&](int i) -> std::int64_t {
      const std::int64_t v = nodes[static_cast<std::size_t>(i)].m_escapeIndexOrTriangleIndex;
      return v >= 0 ? 1 : -v;
    };
    if (extent(0) != size) return false;
    std::vector<bool> seen(static_cast<std::size_t>(triangles), false);
    std::vector<int> pending{0};
    while (!pending.empty()) {
      const int i = pending.back();
      pending.pop_back();
      const btQuantizedBvhNode& node = nodes[static_cast<std::size_t>(i)];
      if (node.isLeafNode()) {
        const int t = node.getTriangleIndex();
        if (node.getPartId() != 0 || t >= triangles || seen[static_cast<std::size_t>(t)]) return false;
        seen[static_cast<std::size_t>(t)] = true;
        btVector3 lo(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT), hi = -lo;
        for (int c = 0; c < 3; ++c) {
          const std::size_t v = 3 * static_cast<std::size_t>(indices[3 * static_cast<std::size_t>(t) + c]);
          const btVector3 corner(vertices[v], vertices[v + 1], vertices[v + 2]);
          lo.setMin(corner);
          hi.setMax(corner);
        }
        unsigned short qlo[3], qhi[3];
        quantizeWithClamp(qlo, lo, 0);
        quantizeWithClamp(qhi, hi, 1);
        if (!holds(node, qlo, qhi)) return false;
        continue;
      }
      // Internal: two subtrees side by side, filling its extent, each inside its box.
      const int left = i + 1;
      if (left >= size) return false;
      const std::int64_t left_extent = extent(left);
      const std::int64_t right = left + left_extent;
      if (right >= size) return false;
      const std::int64_t right_extent = extent(static_cast<int>(right));
      if (1 + left_extent + right_extent != extent(i)) return false;
      for (const std::int64_t child : {std::int64_t(left), right}) {
        const btQuantizedBvhNode& c = nodes[static_cast<std::size_t>(child)];
        if (!holds(node, c.m_quantizedAabbMin, c.m_quantizedAabbMax)) return false;
        pending.push_back(static_cast<int>(child));
      }
    }
    m_quantizedContiguousNodes.resize(size);
    std::memcpy(&m_quantizedContiguousNodes[0], nodes.data(), bytes.size());
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
  kept_ = kept->take(mesh.bvh_nodes, vertices_, indices_, shape_->getLocalAabbMin(), shape_->getLocalAabbMax());
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
