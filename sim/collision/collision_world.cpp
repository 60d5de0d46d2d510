#include "sim/collision/collision_world.hpp"

#include "sim/mesh/solid.hpp"
#include "sim/mesh/triangle_bvh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <set>

#include <btBulletCollisionCommon.h>
#include <BulletCollision/CollisionShapes/btTriangleShape.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btPointCollector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>

namespace sim {
namespace {

// Bullet works in millimetres here: its GJK/EPA are tuned for bodies of 0.1 to 10 units, and
// in metres a 15 mm peg gave penetration depths that were plainly wrong. The API stays in
// metres; only this file sees Bullet units.
constexpr double kUnitsPerMetre = kBulletUnitsPerMetre;

btVector3 to_bullet(const Eigen::Vector3d& v) {
  return btVector3(v.x() * kUnitsPerMetre, v.y() * kUnitsPerMetre, v.z() * kUnitsPerMetre);
}

btTransform to_bullet(const Pose& pose) {
  const Eigen::Matrix3d r = pose.linear();
  return btTransform(btMatrix3x3(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)),
                     to_bullet(Eigen::Vector3d(pose.translation())));
}

// A hull grown beyond its margin to hold corners it leaves out (a simplified hull) keeps that
// growth (Bullet units) in its user index, in steps of a millionth: a distance adds back only
// the margin that lies beyond the mesh, and is never more than the mesh's own.
constexpr double kHeldSteps = 1e6;
void set_held(btCollisionShape& shape, double held) { shape.setUserIndex(static_cast<int>(std::lround(held * kHeldSteps))); }
double held_of(const btCollisionShape* shape) { return std::max(0, shape->getUserIndex()) / kHeldSteps; }

std::unique_ptr<btConvexHullShape> hull_through(const TriangleMesh& mesh, const std::vector<std::uint32_t>& points,
                                                double margin, double held = 0) {
  auto hull = std::make_unique<btConvexHullShape>();
  for (auto index : points) hull->addPoint(to_bullet(mesh.vertices[index]), false);
  hull->recalcLocalAabb();
  hull->setMargin((margin + held) * kUnitsPerMetre);
  set_held(*hull, held * kUnitsPerMetre);
  return hull;
}

// The hull of a mesh's piece, of the corners loading found (mesh.hull_corners): a bore's or
// a stud's inner vertices would only slow every support query of GJK. A convex mesh of many
// corners: its simplified hull (triangle_mesh.hpp), for the same reason.
std::unique_ptr<btConvexHullShape> hull_of(const TriangleMesh& mesh, std::size_t piece, double margin) {
  if (hull_simplified(mesh)) return hull_through(mesh, mesh.coarse_corners, margin, mesh.coarse_margin);
  return hull_through(mesh, piece < mesh.hull_corners.size() ? mesh.hull_corners[piece] : mesh.pieces[piece], margin);
}

// The coarse hull of a one-piece mesh (triangle_mesh.hpp): a few hull corners grown to hold
// the rest, or the hull itself.
std::unique_ptr<btConvexHullShape> coarse_hull_of(const TriangleMesh& mesh, double margin) {
  if (mesh.coarse_corners.empty()) return hull_of(mesh, 0, margin);
  return hull_through(mesh, mesh.coarse_corners, margin, mesh.coarse_margin);
}

constexpr int kCoarse = 1;  // user index 2 of a static body's hull that stands before its BVH

// Keeps the deepest penetration beyond the tolerance, and which static bodies' coarse hulls
// were penetrated beyond it (their exact shapes are asked next).
// With `crossings` on, it also keeps every pair of a moving triangle and a static body's
// triangle that touch or cross, however shallow: their depth by GJK/EPA is the shortest way
// out of two thin triangles, and the volumes they bound are asked next.
struct DeepestContact : btCollisionWorld::ContactResultCallback {
  struct Crossing {
    int self_child;  // of the moving compound
    BodyId body;
    int triangle;    // of the static body's mesh
  };
  const btCollisionObject* self;
  double tolerance;
  std::optional<Contact> deepest;
  int self_child = -1;
  std::set<BodyId> coarse_hits;
  bool keep_crossings = false;
  std::vector<Crossing> crossings;
  int child = -1;  // >= 0: `self` stands for this one child of the moving compound
  bool skip_hulls = false;  // leave out concave bodies' hulls
  BodyId ignore = -1;       // a body left out (CollisionWorld::penetration)

  DeepestContact(const btCollisionObject* s, double t, BodyId leave_out = -1) : self(s), tolerance(t), ignore(leave_out) {}

  bool needsCollision(btBroadphaseProxy* proxy) const override {
    const auto* object = static_cast<const btCollisionObject*>(proxy->m_clientObject);
    if (ignore >= 0 && object->getUserIndex() == ignore) return false;
    if (skip_hulls && object->getUserIndex2() == kCoarse) return false;
    return ContactResultCallback::needsCollision(proxy);
  }

  btScalar addSingleResult(btManifoldPoint& cp, const btCollisionObjectWrapper* a, int, int index_a,
                           const btCollisionObjectWrapper* b, int, int index_b) override {
    const double depth = -cp.getDistance() / kUnitsPerMetre;
    const bool self_is_a = a->getCollisionObject() == self;
    const btCollisionObject* other = self_is_a ? b->getCollisionObject() : a->getCollisionObject();
    if (keep_crossings && other->getCollisionShape()->getShapeType() == TRIANGLE_MESH_SHAPE_PROXYTYPE) {
      crossings.push_back({child >= 0 ? child : (self_is_a ? index_a : index_b), other->getUserIndex(),
                           self_is_a ? index_b : index_a});
    }
    if (depth <= tolerance) return 0;
    if (other->getUserIndex2() == kCoarse) {
      coarse_hits.insert(other->getUserIndex());
      return 0;
    }
    if (deepest && depth <= deepest->depth) return 0;
    Contact c;
    c.body = other->getUserIndex();
    c.depth = depth;
    const btVector3 p = self_is_a ? cp.getPositionWorldOnB() : cp.getPositionWorldOnA();
    c.point = Eigen::Vector3d(p.x(), p.y(), p.z()) / kUnitsPerMetre;
    self_child = child >= 0 ? child : (self_is_a ? a->m_index : b->m_index);
    deepest = c;
    return 0;
  }
};

// How far a shape's surface lies beyond its corners, where its mesh does not: a box holds its
// margin inside its extents; hulls and triangles are grown by theirs (less what a simplified
// hull holds: set_held).
double grown_by(const btCollisionShape* shape) {
  return shape->getShapeType() == BOX_SHAPE_PROXYTYPE ? 0 : shape->getMargin() - held_of(shape);
}

// The corners of a convex child (box, hull or triangle) at `offset` and the same corners
// shifted by `shift` (in its body's frame): their hull is exactly the volume the child sweeps
// while the body moves by `shift` without turning. A box's corners hold its margin, so its
// hull keeps the box's surface where grown_by adds the margin back; a hull's points leave the
// margin out, as the hull's own margin does.
void swept_corners(const btCollisionShape& child, const btTransform& offset, const btVector3& shift,
                   std::vector<btVector3>& points) {
  const auto& polyhedron = static_cast<const btPolyhedralConvexShape&>(child);
  points.clear();
  for (int v = 0; v < polyhedron.getNumVertices(); ++v) {
    btVector3 p;
    polyhedron.getVertex(v, p);
    points.push_back(offset * p);
    points.push_back(offset * p + shift);
  }
}

std::unique_ptr<btConvexHullShape> hull_of_points(const std::vector<btVector3>& points, btScalar margin) {
  auto hull = std::make_unique<btConvexHullShape>(&points[0].getX(), static_cast<int>(points.size()));
  hull->setMargin(margin);
  return hull;
}

// The distance between two convex shapes' surfaces (Bullet units, 0 where they overlap; huge
// where GJK gives no answer) and the normal from b towards a, by GJK (EPA where they overlap).
std::pair<double, btVector3> convex_distance(const btConvexShape* a, const btTransform& ta, const btConvexShape* b,
                                             const btTransform& tb) {
  btVoronoiSimplexSolver simplex;
  btGjkEpaPenetrationDepthSolver epa;
  btGjkPairDetector gjk(a, b, &simplex, &epa);
  btDiscreteCollisionDetectorInterface::ClosestPointInput input;
  input.m_transformA = ta;
  input.m_transformB = tb;
  btPointCollector result;
  gjk.getClosestPoints(input, result, nullptr);
  if (!result.m_hasResult) return {BT_LARGE_FLOAT, btVector3(0, 0, 0)};  // GJK found nothing: no pair to count
  return {std::max(0.0, double(result.m_distance) + grown_by(a) + grown_by(b)), result.m_normalOnBInWorld};
}

// How far apart two boxes are (0 where they overlap): no pair of shapes inside them is nearer.
btScalar box_gap(const btVector3& lo_a, const btVector3& hi_a, const btVector3& lo_b, const btVector3& hi_b) {
  btVector3 gap(0, 0, 0);
  for (int axis = 0; axis < 3; ++axis) gap[axis] = std::max({btScalar(0), lo_a[axis] - hi_b[axis], lo_b[axis] - hi_a[axis]});
  return gap.length();
}

// The box of the surface that distances measure: of a polyhedron's corners (a box's hold its
// margin, hulls and triangles are grown beyond theirs: grown_by). Bullet's own box of a
// triangle holds its margin twice.
void surface_box(const btConvexShape* shape, const btTransform& at, btVector3& lo, btVector3& hi) {
  if (!shape->isPolyhedral()) return shape->getAabb(at, lo, hi);
  const auto* polyhedron = static_cast<const btPolyhedralConvexShape*>(shape);
  lo = btVector3(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT);
  hi = -lo;
  for (int v = 0; v < polyhedron->getNumVertices(); ++v) {
    btVector3 corner;
    polyhedron->getVertex(v, corner);
    corner = at * corner;
    lo.setMin(corner);
    hi.setMax(corner);
  }
}

// Calls `visit` with each convex piece of a static shape (a compound's children, a triangle
// mesh's triangles) whose box comes within `box` (world), and its world transform.
using PieceVisit = std::function<void(const btConvexShape*, const btTransform&)>;
void static_pieces(const btCollisionShape* shape, const btTransform& world, const btVector3& min, const btVector3& max,
                   const PieceVisit& visit) {
  if (shape->isCompound()) {
    const auto* compound = static_cast<const btCompoundShape*>(shape);
    for (int i = 0; i < compound->getNumChildShapes(); ++i) {
      const btTransform child = world * compound->getChildTransform(i);
      btVector3 lo, hi;
      compound->getChildShape(i)->getAabb(child, lo, hi);
      if (TestAabbAgainstAabb2(lo, hi, min, max)) {
        static_pieces(compound->getChildShape(i), child, min, max, visit);
      }
    }
    return;
  }
  if (shape->isConcave()) {
    // The box in the mesh's own frame: the box of the world box's corners.
    const btTransform to_local = world.inverse();
    btVector3 lo(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT), hi = -lo;
    for (int c = 0; c < 8; ++c) {
      const btVector3 corner = to_local * btVector3(c & 1 ? max.x() : min.x(), c & 2 ? max.y() : min.y(), c & 4 ? max.z() : min.z());
      lo.setMin(corner);
      hi.setMax(corner);
    }
    struct Triangles : btTriangleCallback {
      const btCollisionShape* mesh;
      const btTransform* world;
      const PieceVisit* visit;
      void processTriangle(btVector3* t, int, int) override {
        btTriangleShape triangle(t[0], t[1], t[2]);
        triangle.setMargin(mesh->getMargin());
        (*visit)(&triangle, *world);
      }
    } triangles;
    triangles.mesh = shape;
    triangles.world = &world;
    triangles.visit = &visit;
    static_cast<const btConcaveShape*>(shape)->processAllTriangles(&triangles, lo, hi);
    return;
  }
  visit(static_cast<const btConvexShape*>(shape), world);
}

// A convex hull whose points are set anew for each piece: a concave part's swept pieces are
// one per triangle, and a hull allocated for each was a tenth of a plan of a ring stack.
class ReusableHull : public btConvexHullShape {
 public:
  void set(const btVector3* points, int count, btScalar margin, btScalar held) {
    m_unscaledPoints.resize(count);
    std::copy(points, points + count, &m_unscaledPoints[0]);
    setMargin(margin);
    set_held(*this, held);
    recalcLocalAabb();
  }
};

// A convex piece of a moving body, where it stands (world), and the member it belongs to.
// The piece is `shape`, or (null) the hull of `count` corners from `first` on in the list that
// comes with it, with that margin (of which `held` holds corners left out: set_held).
struct MovingPiece {
  const btConvexShape* shape;
  btTransform at;
  const std::string* member;
  std::size_t first = 0;
  int count = 0;
  btScalar margin = 0;
  btScalar held = 0;
  // A piece that closes on its seat along `ahead` (world, unit): static pieces wholly beyond
  // `ends_at` along it are not asked.
  btVector3 ahead{0, 0, 0};
  btScalar ends_at = BT_LARGE_FLOAT;
};

// Where the piece closes along an axis of the world (the usual insertion), the search box
// ends where the piece does: the box query leaves out what lies beyond.
void cut_at_end(const MovingPiece& piece, btVector3& lo, btVector3& hi) {
  if (piece.ends_at >= BT_LARGE_FLOAT) return;
  for (int k = 0; k < 3; ++k) {
    if (piece.ahead[k] > 1 - 1e-9) hi[k] = std::min(hi[k], piece.ends_at);
    if (piece.ahead[k] < -1 + 1e-9) lo[k] = std::max(lo[k], -piece.ends_at);
  }
}

// How far along `axis` a box begins (its least extent).
btScalar box_begins_at(const btVector3& lo, const btVector3& hi, const btVector3& axis) {
  btScalar least = BT_LARGE_FLOAT;
  for (int c = 0; c < 8; ++c) {
    least = std::min(least, btVector3(c & 1 ? hi.x() : lo.x(), c & 2 ? hi.y() : lo.y(), c & 4 ? hi.z() : lo.z()).dot(axis));
  }
  return least;
}

// How far along `axis` the static piece begins (its least extent, margin included).
btScalar begins_at(const btConvexShape* piece, const btTransform& at, const btVector3& axis) {
  if (piece->getShapeType() == TRIANGLE_SHAPE_PROXYTYPE) {
    const auto* t = static_cast<const btTriangleShape*>(piece);
    btScalar least = BT_LARGE_FLOAT;
    for (const btVector3& v : t->m_vertices1) least = std::min(least, (at * v).dot(axis));
    return least - t->getMargin();
  }
  btVector3 lo, hi;
  piece->getAabb(at, lo, hi);
  return box_begins_at(lo, hi, axis);
}

// Whether a triangle of one solid meets one of another where either may reach into the other:
// they meet, and each has a corner behind the other's plane. One lying wholly on the outer
// side of the other's plane (a wall standing on a floor, a block flush against a wall) only
// touches it there, and searching the pair along the surface finds nothing, slowly; a part
// that goes into the other crosses its surface elsewhere. `orientation_*`: the solids'
// (Solid::orientation: -1 where the faces are wound inwards), asked only of triangles that
// meet: a solid is made on first use.
template <class OrientationA, class OrientationB>
bool meet_inside(const TriangleMesh& a, std::size_t ta, const Pose& pa, const OrientationA& orientation_a,
                 const TriangleMesh& b, std::size_t tb, const Pose& pb, const OrientationB& orientation_b) {
  if (ta >= a.triangles.size() || tb >= b.triangles.size()) return false;
  const auto corners = [](const TriangleMesh& m, std::size_t t, const Pose& p) {
    return std::array<Eigen::Vector3d, 3>{p * m.vertices[m.triangles[t][0]], p * m.vertices[m.triangles[t][1]],
                                          p * m.vertices[m.triangles[t][2]]};
  };
  const auto x = corners(a, ta, pa), y = corners(b, tb, pb);
  const Eigen::Vector3d nx = (x[1] - x[0]).cross(x[2] - x[0]), ny = (y[1] - y[0]).cross(y[2] - y[0]);
  if (nx.squaredNorm() == 0 || ny.squaredNorm() == 0) return false;
  constexpr double kInPlane = 1e-9;  // m
  const auto behind = [](const std::array<Eigen::Vector3d, 3>& t, const Eigen::Vector3d& outwards,
                         const Eigen::Vector3d& on_plane) {
    return std::any_of(t.begin(), t.end(), [&](const Eigen::Vector3d& c) { return outwards.dot(c - on_plane) < -kInPlane; });
  };
  const auto point = [](const Eigen::Vector3d& v) { return SolidPoint(v.x(), v.y(), v.z()); };
  return CGAL::do_intersect(SolidKernel::Triangle_3(point(x[0]), point(x[1]), point(x[2])),
                            SolidKernel::Triangle_3(point(y[0]), point(y[1]), point(y[2]))) &&
         behind(x, orientation_b() * ny.normalized(), y[0]) && behind(y, orientation_a() * nx.normalized(), x[0]);
}

// The children of a compound whose boxes overlap a box in its frame.
struct ChildrenIn : btDbvt::ICollide {
  std::vector<int> children;
  void Process(const btDbvtNode* leaf) override { children.push_back(leaf->dataAsInt); }
};

struct Overlapping : btBroadphaseAabbCallback {
  std::vector<const btCollisionObject*> objects;
  bool process(const btBroadphaseProxy* proxy) override {
    objects.push_back(static_cast<const btCollisionObject*>(proxy->m_clientObject));
    return true;
  }
};

}  // namespace

// --- MovingBody ---------------------------------------------------------------------------

struct MovingBody::Impl {
  // `coarse`: every member convex (a one-piece mesh as its hull). `exact`: the same, but a
  // one-piece concave mesh as its triangles, each a convex child; asked only where the coarse
  // body penetrates, since the hull holds the mesh: where the hull does not reach, nothing
  // does. It is made on the first such check: most bodies never need it, and a compound of
  // 10k triangles costs more to make than a sweep.
  struct Shape {
    btCompoundShape compound{true};
    std::vector<std::unique_ptr<btCollisionShape>> shapes;
    std::vector<std::string> member_of_child;  // compound child index -> member name
    btCollisionObject object;
    Shape() { object.setCollisionShape(&compound); }
    void add(const std::string& member, std::unique_ptr<btCollisionShape> shape, const btTransform& offset) {
      compound.addChildShape(offset, shape.get());
      member_of_child.push_back(member);
      shapes.push_back(std::move(shape));
    }
  };
  Shape coarse;
  // Per coarse child, the triangles (in Bullet units) that stand for it in the exact body;
  // empty for a convex child, which stands for itself.
  std::vector<std::vector<std::array<btVector3, 3>>> triangles_of_child;
  double margin = 0;  // of the triangles
  bool has_exact = false;
  mutable std::unique_ptr<Shape> exact;
  // Per coarse child, its mesh (vertices and triangles; null for a convex child), its offset
  // in metres, and the solid it bounds, made when first asked. Per exact child: which coarse
  // child and which of its triangles (-1: a convex child) it is.
  std::vector<std::shared_ptr<const TriangleMesh>> mesh_of_child;
  std::vector<Pose> offset_of_child;
  mutable std::vector<std::unique_ptr<Solid>> solid_of_child;
  mutable std::vector<std::pair<std::size_t, int>> origin_of_exact_child;

  void add(const std::string& member, std::unique_ptr<btCollisionShape> shape, const Pose& offset,
           std::vector<std::array<btVector3, 3>> triangles = {}, std::shared_ptr<const TriangleMesh> mesh = nullptr) {
    has_exact = has_exact || !triangles.empty();
    triangles_of_child.push_back(std::move(triangles));
    mesh_of_child.push_back(std::move(mesh));
    offset_of_child.push_back(offset);
    solid_of_child.emplace_back();
    coarse.add(member, std::move(shape), to_bullet(offset));
  }
  Shape& exact_shape() const {
    if (exact) return *exact;
    exact = std::make_unique<Shape>();
    for (std::size_t i = 0; i < coarse.shapes.size(); ++i) {
      const btTransform& offset = coarse.compound.getChildTransform(static_cast<int>(i));
      const std::string& member = coarse.member_of_child[i];
      if (triangles_of_child[i].empty()) {
        exact->add(member, clone(*coarse.shapes[i]), offset);
        origin_of_exact_child.emplace_back(i, -1);
        continue;
      }
      // Into the compound's box tree in a scattered order (a golden-ratio stride): inserted
      // in the mesh's own order, around a ring, the tree grew into nearly a list (the first
      // check of a ring of 50 000 triangles took 4.4 s; 0.42 s scattered).
      const std::size_t n = triangles_of_child[i].size();
      std::size_t stride = std::max<std::size_t>(1, static_cast<std::size_t>(0.618034 * static_cast<double>(n)));
      while (std::gcd(stride, n) != 1) ++stride;
      for (std::size_t k = 0; k < n; ++k) {
        const std::size_t t = k * stride % n;
        const auto& corners = triangles_of_child[i][t];
        auto triangle = std::make_unique<btTriangleShape>(corners[0], corners[1], corners[2]);
        triangle->setMargin(margin);
        exact->add(member, std::move(triangle), offset);
        origin_of_exact_child.emplace_back(i, static_cast<int>(t));
      }
    }
    return *exact;
  }
  const Solid& solid(std::size_t child) const {
    if (!solid_of_child[child]) solid_of_child[child] = solid_of(*mesh_of_child[child]);
    return *solid_of_child[child];
  }
  static std::unique_ptr<btCollisionShape> clone(const btCollisionShape& shape) {
    if (shape.getShapeType() == BOX_SHAPE_PROXYTYPE) {
      const auto& box = static_cast<const btBoxShape&>(shape);
      auto copy = std::make_unique<btBoxShape>(box.getHalfExtentsWithMargin());  // it takes the margin off itself
      copy->setMargin(box.getMargin());
      return copy;
    }
    const auto& hull = static_cast<const btConvexHullShape&>(shape);
    auto copy = std::make_unique<btConvexHullShape>(&hull.getUnscaledPoints()->getX(), hull.getNumPoints());
    copy->setMargin(hull.getMargin());
    return copy;
  }
};

MovingBody::MovingBody() : impl_(std::make_unique<Impl>()) {}
MovingBody::~MovingBody() = default;
MovingBody::MovingBody(MovingBody&& other) noexcept = default;
MovingBody& MovingBody::operator=(MovingBody&& other) noexcept = default;

void MovingBody::add_mesh(const std::string& member, const TriangleMesh& mesh, const Pose& offset, double margin) {
  add_mesh(member, std::make_shared<const TriangleMesh>(mesh), offset, margin);
}

void MovingBody::add_mesh(const std::string& member, std::shared_ptr<const TriangleMesh> shared, const Pose& offset,
                          double margin) {
  const TriangleMesh& mesh = *shared;
  for (std::size_t piece = 0; piece < mesh.pieces.size(); ++piece) {
    for (auto index : mesh.pieces[piece]) radius_ = std::max(radius_, (offset * mesh.vertices[index]).norm());
    auto hull = hull_of(mesh, piece, margin);
    if (pieces_are_exact(mesh)) {
      impl_->add(member, std::move(hull), offset);
      continue;
    }
    // One piece, maybe concave (a bracket, a housing with a bore): its hull is only the
    // coarse test, of few corners grown to hold the rest where loading made it so; the exact
    // one goes by its triangles.
    hull = coarse_hull_of(mesh, margin);
    std::vector<std::array<btVector3, 3>> triangles;
    triangles.reserve(mesh.triangles.size());
    for (const auto& t : mesh.triangles) {
      triangles.push_back({to_bullet(mesh.vertices[t[0]]), to_bullet(mesh.vertices[t[1]]), to_bullet(mesh.vertices[t[2]])});
    }
    impl_->margin = margin * kUnitsPerMetre;
    impl_->add(member, std::move(hull), offset, std::move(triangles), shared);
  }
}

void MovingBody::add_box(const std::string& member, const Eigen::Vector3d& half_extents, const Pose& offset,
                         double margin) {
  auto box = std::make_unique<btBoxShape>(to_bullet(half_extents));
  box->setMargin(margin * kUnitsPerMetre);
  radius_ = std::max(radius_, offset.translation().norm() + half_extents.norm());
  impl_->add(member, std::move(box), offset);
}

bool MovingBody::empty() const { return impl_->coarse.shapes.empty(); }

Pose interpolate(const Pose& from, const Pose& to, double s) {
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::Quaterniond(from.linear()).slerp(s, Eigen::Quaterniond(to.linear())).toRotationMatrix();
  pose.translation() = (1 - s) * from.translation() + s * to.translation();
  return pose;
}

// --- CollisionWorld -----------------------------------------------------------------------

// Bullet's default pools (4096 manifolds and algorithms, some 7 MB, zeroed) cost more to set
// up than a plan of a small product; a check of one moving body needs a few, and Bullet
// allocates past its pool when it must.
btDefaultCollisionConstructionInfo small_pools() {
  btDefaultCollisionConstructionInfo info;
  info.m_defaultMaxPersistentManifoldPoolSize = 256;
  info.m_defaultMaxCollisionAlgorithmPoolSize = 256;
  return info;
}

struct CollisionWorld::Impl {
  btDefaultCollisionConfiguration configuration{small_pools()};
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btCollisionWorld world{&dispatcher, &broadphase, &configuration};

  struct SharedMesh {
    std::shared_ptr<const TriangleMesh> mesh;
    btCollisionShape* shape = nullptr;              // one of the two below
    std::unique_ptr<btCompoundShape> pieces;        // convex pieces
    std::unique_ptr<StaticMeshShape> triangles;     // or a concave mesh's triangles
    std::unique_ptr<btCollisionShape> coarse;  // a concave mesh's hull, asked before its BVH
    std::vector<std::unique_ptr<btCollisionShape>> hulls;
    std::unique_ptr<Solid> solid;  // a concave mesh's volume, made when first asked
  };
  std::map<const TriangleMesh*, SharedMesh> meshes;
  struct Body {
    std::string name;
    std::unique_ptr<btCollisionShape> own_shape;  // boxes; meshes share theirs
    std::unique_ptr<btCollisionObject> object;    // in the world
    // A concave mesh's triangle BVH, outside the world: `object` is then its hull (user
    // index 2 kCoarse), and only a body that penetrates that is checked against the BVH. A
    // ring on the ring below touches thousands of triangles, and its hull not at all.
    std::unique_ptr<btCollisionObject> exact;
    const TriangleMesh* mesh = nullptr;  // a concave mesh's, for its solid
    Pose pose = Pose::Identity();
  };
  std::map<BodyId, Body> bodies;
  BodyId next_id = 0;

  // A mesh authored as convex pieces becomes a compound of their hulls: holes stay open and
  // penetration depths are those of convex pairs; a convex one-piece mesh is its hull, exact.
  // Another one-piece mesh may be concave, so it becomes a triangle BVH (whose depths are per
  // triangle, less exact for thin walls, and which costs a GJK per triangle near contact).
  btCollisionShape* static_shape_for(std::shared_ptr<const TriangleMesh> mesh, double margin) {
    auto [it, inserted] = meshes.try_emplace(mesh.get());
    SharedMesh& shared = it->second;
    if (!inserted) return shared.shape;
    shared.mesh = mesh;
    if (pieces_are_exact(*mesh)) {
      auto compound = std::make_unique<btCompoundShape>(true, static_cast<int>(mesh->pieces.size()));
      for (std::size_t piece = 0; piece < mesh->pieces.size(); ++piece) {
        auto hull = hull_of(*mesh, piece, margin);
        compound->addChildShape(btTransform::getIdentity(), hull.get());
        shared.hulls.push_back(std::move(hull));
      }
      shared.pieces = std::move(compound);
      return shared.shape = shared.pieces.get();
    }
    shared.triangles = std::make_unique<StaticMeshShape>(*mesh, margin);
    shared.coarse = coarse_hull_of(*mesh, margin);
    return shared.shape = &shared.triangles->shape();
  }
  btCollisionShape* coarse_shape_of(const TriangleMesh* mesh) const {
    const auto it = meshes.find(mesh);
    return it == meshes.end() ? nullptr : it->second.coarse.get();
  }
  const Solid& solid_of_body(const Body& body) {
    SharedMesh& shared = meshes.at(body.mesh);
    if (!shared.solid) shared.solid = solid_of(*shared.mesh);
    return *shared.solid;
  }

  // Every body the object penetrates, concave static ones by their hull first and by their
  // triangles only where the hull is penetrated.
  void contact_test(btCollisionObject& object, DeepestContact& callback) {
    world.contactTest(&object, callback);
    for (BodyId hit : callback.coarse_hits) world.contactPairTest(&object, bodies.at(hit).exact.get(), callback);
  }

  BodyId add(const std::string& name, btCollisionShape* shape, std::unique_ptr<btCollisionShape> own, const Pose& pose,
             btCollisionShape* coarse = nullptr, const TriangleMesh* mesh = nullptr) {
    const auto object_of = [&](btCollisionShape* s) {
      auto object = std::make_unique<btCollisionObject>();
      object->setCollisionShape(s);
      object->setWorldTransform(to_bullet(pose));
      object->setUserIndex(next_id);
      return object;
    };
    Body body{name, std::move(own), object_of(coarse ? coarse : shape), nullptr, mesh, pose};
    if (coarse) {
      body.object->setUserIndex2(kCoarse);
      body.exact = object_of(shape);
    }
    world.addCollisionObject(body.object.get());
    bodies[next_id] = std::move(body);
    return next_id++;
  }

  // The nearest pair of a moving piece and a piece of the `near` bodies within `threshold`
  // (Bullet units) that `counts` keeps. Piece by piece, GJK on each pair within reach:
  // Bullet's own closest-point query builds a collision algorithm per call, which cost more
  // than the distances.
  std::optional<Clearance> nearest_of(const std::vector<MovingPiece>& pieces,
                                      const std::vector<const btCollisionObject*>& near, btScalar threshold,
                                      const ClearanceFilter& counts, const std::vector<btVector3>& corners = {}) const {
    std::optional<Clearance> best;
    ReusableHull hull;
    for (MovingPiece piece : pieces) {
      if (!piece.shape) {
        hull.set(&corners[piece.first], piece.count, piece.margin, piece.held);
        piece.shape = &hull;
      }
      btVector3 box_lo, box_hi, surface_lo, surface_hi;
      piece.shape->getAabb(piece.at, box_lo, box_hi);
      surface_box(piece.shape, piece.at, surface_lo, surface_hi);
      for (const btCollisionObject* other : near) {
        // Only what is nearer than the nearest so far: the box shrinks as the search goes.
        const btScalar within = best ? static_cast<btScalar>(best->distance * kUnitsPerMetre) : threshold;
        btVector3 lo = box_lo - btVector3(within, within, within), hi = box_hi + btVector3(within, within, within);
        cut_at_end(piece, lo, hi);
        const Body& b = bodies.at(other->getUserIndex());
        const btCollisionObject* exact = b.exact ? b.exact.get() : b.object.get();
        static_pieces(exact->getCollisionShape(), exact->getWorldTransform(), lo, hi,
                      [&](const btConvexShape* against, const btTransform& against_at) {
                        if (piece.ends_at < BT_LARGE_FLOAT && begins_at(against, against_at, piece.ahead) > piece.ends_at) {
                          return;
                        }
                        // A pair whose boxes lie as far apart as the nearest so far cannot be
                        // nearer (a ring held 1 mm above another asked GJK of every pair of
                        // facing triangles: 16.7 s at 50k triangles, 2.9 s now).
                        if (best) {
                          btVector3 lo_against, hi_against;
                          surface_box(against, against_at, lo_against, hi_against);
                          if (box_gap(surface_lo, surface_hi, lo_against, hi_against) >= best->distance * kUnitsPerMetre) return;
                        }
                        const auto [distance, normal] = convex_distance(piece.shape, piece.at, against, against_at);
                        const double metres = distance / kUnitsPerMetre;
                        if (distance > threshold || (best && metres >= best->distance)) return;
                        Clearance c;
                        c.body = other->getUserIndex();
                        c.distance = metres;
                        c.normal = Eigen::Vector3d(normal.x(), normal.y(), normal.z());
                        c.member = *piece.member;
                        if (counts && !counts(c)) return;
                        best = c;
                      });
      }
    }
    if (best) best->body_name = bodies.at(best->body).name;
    return best;
  }
};


CollisionWorld::CollisionWorld(CollisionOptions options) : impl_(std::make_unique<Impl>()), options_(options) {}
CollisionWorld::~CollisionWorld() {
  for (auto& [id, body] : impl_->bodies) impl_->world.removeCollisionObject(body.object.get());
}

BodyId CollisionWorld::add_static_mesh(const std::string& name, std::shared_ptr<const TriangleMesh> mesh, const Pose& pose) {
  btCollisionShape* shape = impl_->static_shape_for(mesh, options_.shape_margin);
  btCollisionShape* coarse = impl_->coarse_shape_of(mesh.get());
  return impl_->add(name, shape, nullptr, pose, coarse, coarse ? mesh.get() : nullptr);
}

BodyId CollisionWorld::add_static_box(const std::string& name, const Eigen::Vector3d& half_extents, const Pose& pose) {
  auto box = std::make_unique<btBoxShape>(to_bullet(half_extents));
  box->setMargin(options_.shape_margin * kUnitsPerMetre);
  btCollisionShape* shape = box.get();
  return impl_->add(name, shape, std::move(box), pose);
}

void CollisionWorld::remove(BodyId body) {
  const auto it = impl_->bodies.find(body);
  if (it == impl_->bodies.end()) return;
  impl_->world.removeCollisionObject(it->second.object.get());
  impl_->bodies.erase(it);
}

std::optional<Contact> CollisionWorld::penetration(const MovingBody& body, const Pose& pose, BodyId ignore) const {
  ++checks_;
  MovingBody::Impl& moving = *body.impl_;
  const double tolerance = options_.contact_tolerance;
  const btTransform at = to_bullet(pose);
  const auto contact_of = [&](const DeepestContact& found, const MovingBody::Impl::Shape& shape) -> std::optional<Contact> {
    if (!found.deepest) return std::nullopt;
    Contact c = *found.deepest;
    c.body_name = impl_->bodies.at(c.body).name;
    const auto& members = shape.member_of_child;
    if (found.self_child >= 0 && found.self_child < static_cast<int>(members.size())) c.member = members[found.self_child];
    return c;
  };
  // The coarse body first. One with an exact body stops at concave bodies' hulls: the exact
  // body is asked against their triangles right away (the coarse hull's GJK against each of
  // the thousands of triangles near it was half the time of a ring set into a ring).
  moving.coarse.object.setWorldTransform(at);
  DeepestContact coarse(&moving.coarse.object, tolerance, ignore);
  if (!moving.has_exact) {
    impl_->contact_test(moving.coarse.object, coarse);
    return contact_of(coarse, moving.coarse);
  }
  impl_->world.contactTest(&moving.coarse.object, coarse);
  if (!coarse.deepest && coarse.coarse_hits.empty()) return std::nullopt;

  // Where a concave moving member's triangles touch or cross a concave static body's: how deep
  // each such triangle lies in the other's volume, searched over the whole triangle
  // (sim::deepest_inside: a finely tessellated ring's wall 4 mm into the ring below, whose
  // triangles GJK/EPA let go 0.1 mm apart; a channel's long face crossing another channel's
  // walls between its corners and its middle). Closed meshes only: an open one has no inside.
  // Each triangle once per member and static body (one that rests on a part may go into the
  // next; the static body's are kept while it is asked). The first point deeper than the
  // tolerance ends the search: its depth is then a least one (asking them all took 23 s for
  // a ring of 50 000 triangles 0.4 mm into another).
  std::set<std::pair<std::size_t, int>> moving_done;  // (member, its triangle)
  std::set<std::pair<int, std::size_t>> static_done;  // (the static body's triangle, the member)
  const double resolution = tolerance / 2;
  const auto inside_other = [&](const std::vector<DeepestContact::Crossing>& crossings) -> std::optional<Contact> {
    const auto deep_in = [&](const Solid& into, const TriangleMesh& mesh, std::size_t t, const Pose& to_into,
                             const Pose& to_world, BodyId b, const std::string& member) -> std::optional<Contact> {
      const auto& tri = mesh.triangles[t];
      const auto deep = deepest_inside(into, {to_into * mesh.vertices[tri[0]], to_into * mesh.vertices[tri[1]],
                                              to_into * mesh.vertices[tri[2]]}, tolerance, resolution);
      if (!deep) return std::nullopt;
      Contact c;
      c.body = b;
      c.body_name = impl_->bodies.at(b).name;
      c.member = member;
      c.depth = deep->depth;
      c.point = to_world * (to_into.inverse() * deep->point);
      return c;
    };
    for (const auto& crossing : crossings) {
      const auto body_it = impl_->bodies.find(crossing.body);
      if (crossing.self_child < 0 || crossing.self_child >= static_cast<int>(moving.origin_of_exact_child.size()) ||
          body_it == impl_->bodies.end() || !body_it->second.mesh) {
        continue;
      }
      const auto& origin = moving.origin_of_exact_child[static_cast<std::size_t>(crossing.self_child)];
      const std::size_t child = origin.first;  // not a structured binding: the lambdas below capture it
      const int triangle = origin.second;
      if (triangle < 0 || !moving.mesh_of_child[child]) continue;
      const Impl::Body& fixed = body_it->second;
      const TriangleMesh& moving_mesh = *moving.mesh_of_child[child];
      const TriangleMesh& fixed_mesh = *impl_->meshes.at(fixed.mesh).mesh;
      const Pose member_pose = pose * moving.offset_of_child[child];
      const std::string& member = moving.coarse.member_of_child[child];
      // Only triangles that meet where one may reach into the other (meet_inside): a pair
      // that only touches (a face resting on a face, a wall standing on a floor, a tenon
      // 0.04 mm clear in its mortise) would be searched along the surface for nothing.
      const auto moving_solid = [&]() -> const Solid& { return moving.solid(child); };
      const auto fixed_solid = [&]() -> const Solid& { return impl_->solid_of_body(fixed); };
      if (!meet_inside(moving_mesh, static_cast<std::size_t>(triangle), member_pose, [&] { return moving_solid().orientation; },
                       fixed_mesh, static_cast<std::size_t>(crossing.triangle), fixed.pose,
                       [&] { return fixed_solid().orientation; })) {
        continue;
      }
      if (moving_done.insert({child, triangle}).second) {
        if (auto hit = deep_in(fixed_solid(), moving_mesh, static_cast<std::size_t>(triangle), fixed.pose.inverse() * member_pose,
                               member_pose, crossing.body, member)) {
          return hit;
        }
      }
      if (static_done.insert({crossing.triangle, child}).second) {
        if (auto hit = deep_in(moving_solid(), fixed_mesh, static_cast<std::size_t>(crossing.triangle),
                               member_pose.inverse() * fixed.pose, fixed.pose, crossing.body, member)) {
          return hit;
        }
      }
    }
    return std::nullopt;
  };

  // The exact body: against boxes and convex bodies all at once; then against each concave
  // body whose hull the coarse body penetrates, child by child, so that the volumes can end the
  // search at the first child found inside. A ring 0.4 mm into another of 50 000 triangles
  // took 9.9 s before: GJK/EPA of every bottom triangle against the hull below, then of every
  // touching pair of triangles, and only then the volumes.
  MovingBody::Impl::Shape& exact = moving.exact_shape();
  exact.object.setWorldTransform(at);
  DeepestContact callback(&exact.object, tolerance, ignore);
  callback.skip_hulls = true;
  impl_->world.contactTest(&exact.object, callback);
  btCollisionObject probe;
  callback.self = &probe;
  const btDbvt* tree = exact.compound.getDynamicAabbTree();
  for (BodyId b : coarse.coarse_hits) {
    moving_done.clear();
    static_done.clear();
    btCollisionObject& fixed = *impl_->bodies.at(b).exact;
    btVector3 min, max;
    fixed.getCollisionShape()->getAabb(at.inverse() * fixed.getWorldTransform(), min, max);
    ChildrenIn near;
    tree->collideTV(tree->m_root, btDbvtVolume::FromMM(min, max), near);
    std::sort(near.children.begin(), near.children.end());
    for (int child : near.children) {
      probe.setCollisionShape(exact.compound.getChildShape(child));
      probe.setWorldTransform(at * exact.compound.getChildTransform(child));
      callback.child = child;
      callback.keep_crossings = !callback.deepest;  // volumes matter only while nothing is deeper
      callback.crossings.clear();
      impl_->world.contactPairTest(&probe, &fixed, callback);
      if (callback.deepest) continue;
      if (auto hit = inside_other(callback.crossings)) return hit;
    }
  }
  return contact_of(callback, exact);
}

std::optional<Clearance> CollisionWorld::nearest(const MovingBody& body, const Pose& pose, double reach,
                                                 const ClearanceFilter& counts) const {
  ++checks_;
  // Exact shapes only: a coarse hull is grown to hold its mesh and would tell too little room.
  MovingBody::Impl::Shape& shape = body.impl_->has_exact ? body.impl_->exact_shape() : body.impl_->coarse;
  const btTransform at = to_bullet(pose);
  const btScalar threshold = static_cast<btScalar>(reach * kUnitsPerMetre);
  const btVector3 pad(threshold, threshold, threshold);
  btVector3 min, max;
  shape.compound.getAabb(at, min, max);
  Overlapping near;
  impl_->broadphase.aabbTest(min - pad, max + pad, near);
  std::vector<MovingPiece> pieces;
  for (int i = 0; i < shape.compound.getNumChildShapes(); ++i) {
    pieces.push_back({static_cast<const btConvexShape*>(shape.compound.getChildShape(i)),
                      at * shape.compound.getChildTransform(i), &shape.member_of_child[static_cast<std::size_t>(i)]});
  }
  return impl_->nearest_of(pieces, near.objects, threshold, counts);
}

// Without turning, one distance per pair of pieces covers the whole move: the distance to a
// child's swept volume (swept_corners) is the least it comes to along the move. Sampling took one
// per pair and millimetre. A pair is judged where it comes nearest: one that closes head-on
// at the move's end is a seat, which `counts` leaves out. For the `closing` member, what lies
// wholly beyond the end of a piece's sweep is not asked at all: the piece never comes beside
// it, and a part lowered onto a concave one asked every pair of their facing triangles.
std::optional<Clearance> CollisionWorld::nearest_translating(const MovingBody& body, const Pose& from,
                                                             const Eigen::Vector3d& shift, double reach,
                                                             const ClearanceFilter& counts,
                                                             const std::string& closing) const {
  ++checks_;
  const MovingBody::Impl& moving = *body.impl_;
  const btCompoundShape& coarse = moving.coarse.compound;
  const btTransform at = to_bullet(from);
  btTransform end = at;
  end.setOrigin(at.getOrigin() + to_bullet(shift));
  const btVector3 local_shift = to_bullet(Eigen::Vector3d(from.linear().transpose() * shift));
  const Eigen::Vector3d direction = shift.norm() > 0 ? Eigen::Vector3d(shift.normalized()) : Eigen::Vector3d::Zero();
  const btVector3 ahead(direction.x(), direction.y(), direction.z());
  const btScalar threshold = static_cast<btScalar>(reach * kUnitsPerMetre);
  const btVector3 pad(threshold, threshold, threshold);
  btVector3 min, max, min_end, max_end;
  coarse.getAabb(at, min, max);
  coarse.getAabb(end, min_end, max_end);
  Overlapping near;
  min.setMin(min_end);
  max.setMax(max_end);
  impl_->broadphase.aabbTest(min - pad, max + pad, near);
  if (near.objects.empty()) return std::nullopt;
  // Piece by piece: each convex child, and a concave member's triangles (its exact shape,
  // whose compound of 10k children took longer to build than the distances). Swept hulls
  // only for the pieces that come within reach of a near body's box.
  std::vector<btVector3> corners;  // of every swept piece, one after the other
  std::vector<MovingPiece> pieces;
  std::vector<btVector3> points;  // a piece's corners and the same shifted, in the body's frame
  std::vector<btVector3> in_world;
  const auto consider = [&](const std::string& member, btScalar margin, btScalar held) {
    if (points.empty()) return;
    in_world.clear();
    btVector3 lo(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT), hi = -lo;
    for (const btVector3& p : points) {
      in_world.push_back(at * p);
      lo.setMin(in_world.back());
      hi.setMax(in_world.back());
    }
    MovingPiece piece{nullptr, at, &member, corners.size(), static_cast<int>(points.size()), margin, held};
    if (member == closing && ahead.length2() > 0) {
      piece.ahead = ahead;
      piece.ends_at = -BT_LARGE_FLOAT;
      for (const btVector3& p : in_world) piece.ends_at = std::max(piece.ends_at, p.dot(ahead));
      piece.ends_at += margin;
    }
    // Near a body's box, and not wholly short of it (nothing in it would be asked).
    const btVector3 grown = pad + btVector3(margin, margin, margin);
    const bool within_reach = std::any_of(near.objects.begin(), near.objects.end(), [&](const btCollisionObject* o) {
      const btBroadphaseProxy* proxy = o->getBroadphaseHandle();
      return TestAabbAgainstAabb2(lo - grown, hi + grown, proxy->m_aabbMin, proxy->m_aabbMax) &&
             (piece.ends_at >= BT_LARGE_FLOAT || box_begins_at(proxy->m_aabbMin, proxy->m_aabbMax, ahead) <= piece.ends_at);
    });
    if (!within_reach) return;
    corners.insert(corners.end(), points.begin(), points.end());
    pieces.push_back(piece);
  };
  for (int i = 0; i < coarse.getNumChildShapes(); ++i) {
    const btTransform& offset = coarse.getChildTransform(i);
    const std::string& member = moving.coarse.member_of_child[static_cast<std::size_t>(i)];
    const auto& triangles = moving.triangles_of_child[static_cast<std::size_t>(i)];
    if (triangles.empty()) {
      swept_corners(*coarse.getChildShape(i), offset, local_shift, points);
      consider(member, coarse.getChildShape(i)->getMargin(), static_cast<btScalar>(held_of(coarse.getChildShape(i))));
      continue;
    }
    for (const auto& t : triangles) {
      points.clear();
      for (const btVector3& corner : t) {
        points.push_back(offset * corner);
        points.push_back(offset * corner + local_shift);
      }
      consider(member, static_cast<btScalar>(moving.margin), 0);
    }
  }
  return impl_->nearest_of(pieces, near.objects, threshold, counts, corners);
}

namespace {

struct AnyOverlap : btBroadphaseAabbCallback {
  bool found = false;
  bool process(const btBroadphaseProxy*) override {
    found = true;
    return false;
  }
};

}  // namespace

// The coarse body's swept volume (swept_corners, child by child) holds it at every pose of the
// move, so it reaches at least as deep as any of them: when it is clear, so is the whole move.
bool CollisionWorld::clear_translation(const MovingBody& body, const Pose& from, const Eigen::Vector3d& shift) const {
  const btCompoundShape& coarse = body.impl_->coarse.compound;
  const btVector3 d = to_bullet(shift);
  btCompoundShape swept(true, coarse.getNumChildShapes());
  std::vector<std::unique_ptr<btConvexHullShape>> hulls;
  std::vector<btVector3> points;
  for (int i = 0; i < coarse.getNumChildShapes(); ++i) {
    swept_corners(*coarse.getChildShape(i), coarse.getChildTransform(i), d, points);
    hulls.push_back(hull_of_points(points, coarse.getChildShape(i)->getMargin()));
    swept.addChildShape(btTransform::getIdentity(), hulls.back().get());
  }
  btCollisionObject object;
  object.setCollisionShape(&swept);
  object.setWorldTransform(to_bullet(from));
  DeepestContact callback(&object, options_.contact_tolerance);
  ++checks_;
  impl_->contact_test(object, callback);
  return !callback.deepest;
}

// Recursive: a stretch of the sweep whose bounding box (both ends, padded for turning)
// overlaps no body is free as a whole, and so is a stretch without turning whose swept volume
// is clear; the rest is halved down to linear_step and sampled. Samples go in order along
// the sweep, so the first collision is the one reported.
std::optional<Contact> CollisionWorld::sweep(const MovingBody& body, const Pose& from, const Pose& to, BodyId ignore) const {
  const double angle = Eigen::Quaterniond(from.linear()).angularDistance(Eigen::Quaterniond(to.linear()));
  const double travel = (to.translation() - from.translation()).norm() + angle * body.radius();
  const btCollisionShape& shape = body.impl_->coarse.compound;
  const double pad = (angle * body.radius() + options_.shape_margin) * kUnitsPerMetre;
  // Only for convex members: the hull of a concave one-piece member reaches into what it
  // mates with (a brick's hull into the studs below), and its swept volume would only fail.
  const bool translating = angle < 1e-9 && !body.impl_->has_exact && ignore < 0;

  std::optional<Contact> hit;
  auto visit = [&](auto&& self, double s0, double s1, bool check_start) -> bool {
    const Pose a = interpolate(from, to, s0), b = interpolate(from, to, s1);
    btVector3 min_a, max_a, min_b, max_b;
    shape.getAabb(to_bullet(a), min_a, max_a);
    shape.getAabb(to_bullet(b), min_b, max_b);
    min_a.setMin(min_b);
    max_a.setMax(max_b);
    const btVector3 padding(pad * (s1 - s0), pad * (s1 - s0), pad * (s1 - s0));
    AnyOverlap overlap;
    impl_->broadphase.aabbTest(min_a - padding, max_a + padding, overlap);
    if (!overlap.found) return false;
    const bool long_stretch = (s1 - s0) * travel > 16 * options_.linear_step;
    if (translating && long_stretch && clear_translation(body, a, a.linear().transpose() * (b.translation() - a.translation()))) {
      return false;
    }
    if ((s1 - s0) * travel <= options_.linear_step) {
      for (auto [s, pose] : {std::pair{s0, a}, std::pair{s1, b}}) {
        if (s == s0 && !check_start) continue;
        if (auto contact = penetration(body, pose, ignore)) {
          contact->fraction = s;
          hit = contact;
          return true;
        }
      }
      return false;
    }
    const double mid = (s0 + s1) / 2;
    return self(self, s0, mid, check_start) || self(self, mid, s1, false);
  };
  visit(visit, 0.0, 1.0, true);
  return hit;
}

std::optional<Clearance> CollisionWorld::nearest_along(const MovingBody& body, const Pose& from, const Pose& to,
                                                       double reach, const ClearanceFilter& counts,
                                                       const std::string& closing) const {
  const double angle = Eigen::Quaterniond(from.linear()).angularDistance(Eigen::Quaterniond(to.linear()));
  const double travel = (to.translation() - from.translation()).norm() + angle * body.radius();
  const bool translating = angle < 1e-9;
  const btCollisionShape& shape = body.impl_->coarse.compound;
  const double pad = (angle * body.radius() + reach) * kUnitsPerMetre;
  std::optional<Clearance> best;
  const auto keep = [&](std::optional<Clearance> c) {
    if (c && (!best || c->distance < best->distance)) best = c;
  };
  // Only what is nearer than the nearest so far matters: Bullet then leaves more pairs out.
  const auto within = [&] { return best ? best->distance : reach; };
  // As sweep: a stretch whose box, grown by the reach, overlaps no body is skipped. The rest
  // is halved: without turning, down to stretches of four times the reach, each measured
  // whole (nearest_translating; shorter stretches keep its boxes small); else down to
  // linear_step, sampled at its ends.
  auto visit = [&](auto&& self, double s0, double s1) -> void {
    const Pose a = interpolate(from, to, s0), b = interpolate(from, to, s1);
    btVector3 min_a, max_a, min_b, max_b;
    shape.getAabb(to_bullet(a), min_a, max_a);
    shape.getAabb(to_bullet(b), min_b, max_b);
    min_a.setMin(min_b);
    max_a.setMax(max_b);
    const btVector3 padding(pad, pad, pad);
    AnyOverlap overlap;
    impl_->broadphase.aabbTest(min_a - padding, max_a + padding, overlap);
    if (!overlap.found) return;
    const double length = (s1 - s0) * travel;
    if (translating && length <= std::max(4 * reach, options_.linear_step)) {
      keep(nearest_translating(body, a, b.translation() - a.translation(), within(), counts, closing));
      return;
    }
    if (!translating && length <= options_.linear_step) {
      keep(nearest(body, b, within(), counts));
      return;
    }
    const double mid = (s0 + s1) / 2;
    self(self, s0, mid);
    self(self, mid, s1);
  };
  if (!translating) keep(nearest(body, from, reach, counts));
  visit(visit, 0.0, 1.0);
  return best;
}

}  // namespace sim
