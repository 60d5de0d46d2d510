// Gravity two ways, on states whose answer is known (issue #31 item 2: choose by measurement):
// the static support analysis the planner asks (twin::StabilityAnalysis: contact forces by
// linear programming) and settling the state in Bullet's dynamics (every part a rigid body of
// convex hulls, one per piece of its mesh, fastened parts joined by fixed constraints; 0.5 s
// at 240 Hz; a part "moved" if a corner of its box went more than 1 mm).
//  - stacks: blocks stacked at random offsets (tests/support/generated_products.hpp), the
//    whole stack upright; truth from the boxes: at each unglued face between two blocks (and
//    the bottom block's on the station), the centre of mass of all above lies inside the face
//    they share. Seeds where a centre lies within 0.5 mm of an edge are left out.
//  - posts: posts standing on their shoulders in a beam's mortises (play 0 to 0.3 mm), base
//    and posts: they stand. The beam is one concave piece, as CAD exports write it.
//  - cranfield: every intermediate state of its plan (the cell builds it): they stand.
// Upright gravity for both (the planner's 5-degree margin would cost the dynamics one settle
// per direction). Counters: states asked, wrong answers each way; time per state. Run by hand
// (Release): build/release/bin/bench_gravity; figures in docs/performance.md, "Gravity".

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>
#include <btBulletDynamicsCommon.h>

#include "tests/support/generated_products.hpp"
#include "twin/planning/assembly_planner.hpp"
#include "twin/planning/path_planner.hpp"
#include "twin/planning/sequence_planner.hpp"
#include "twin/planning/stability.hpp"

namespace {

// A state to ask about, and what is true of it.
struct Case {
  const twin::LoadedProduct* product;
  std::vector<twin::PartIndex> parts;
  bool stands;
};

std::vector<bool> fastened_among(const twin::Product& product, const std::vector<twin::PartIndex>& parts) {
  std::vector<bool> in(product.parts().size(), false), fastened;
  for (twin::PartIndex p : parts) in[p] = true;
  for (const auto& c : product.connections()) fastened.push_back(c.joint.fastens() && in[c.part1] && in[c.part2]);
  return fastened;
}

bool stands_static(const twin::StabilityAnalysis& analysis, const Case& c) {
  std::vector<twin::PlacedPart> placed;
  for (twin::PartIndex p : c.parts) placed.push_back({p, c.product->product.parts()[p].final_pose});
  return !analysis.check(placed, {}, fastened_among(c.product->product, c.parts)).has_value();
}

btVector3 mm(const Eigen::Vector3d& metres) { return btVector3(metres.x() * 1000, metres.y() * 1000, metres.z() * 1000); }

// Volume and centre (mm) of a closed mesh where it stands; its box's centre where it is not closed.
std::pair<double, btVector3> mass_centre(const sim::TriangleMesh& mesh, const twin::Pose& pose) {
  double volume = 0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = pose * mesh.vertices[t[0]], b = pose * mesh.vertices[t[1]], c = pose * mesh.vertices[t[2]];
    const double v = a.dot(b.cross(c)) / 6;
    volume += v;
    moment += v * (a + b + c) / 4;
  }
  if (mesh.repairs.open_edges > 0 || std::abs(volume) < 1e-15) {
    return {mesh.bounds.volume() * 1e9, mm(pose * mesh.bounds.center())};
  }
  return {std::abs(volume) * 1e9, mm(moment / volume)};
}

// Settles the state under gravity in a world of its own; whether nothing moved.
bool stands_dynamic(const Case& c, int solver_iterations) {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
  world.setGravity(btVector3(0, -9810, 0));  // mm/s^2
  // Face-to-face contacts clipped whole (SAT on the hulls' faces), not gathered a point a step:
  // a block resting on another from its first step, not on one corner of it.
  world.getDispatchInfo().m_enableSatConvex = true;
  world.getSolverInfo().m_numIterations = solver_iterations;

  btBoxShape table_shape(btVector3(2000, 50, 2000));
  btRigidBody table(btRigidBody::btRigidBodyConstructionInfo(0, nullptr, &table_shape));
  table.setWorldTransform(btTransform(btQuaternion::getIdentity(), btVector3(0, -50, 0)));
  world.addRigidBody(&table);

  std::vector<std::unique_ptr<btConvexHullShape>> hulls;
  std::vector<std::unique_ptr<btCompoundShape>> shapes;
  std::vector<std::unique_ptr<btRigidBody>> bodies(c.product->product.parts().size());
  std::vector<std::array<btVector3, 8>> corners;  // each body's box corners, about its centre
  std::vector<btVector3> centres;                 // where each body's centre starts
  std::vector<twin::PartIndex> order;
  for (twin::PartIndex p : c.parts) {
    const sim::TriangleMesh& mesh = *c.product->meshes[p];
    const twin::Pose& pose = c.product->product.parts()[p].final_pose;
    const auto [volume, centre] = mass_centre(mesh, pose);
    auto shape = std::make_unique<btCompoundShape>();
    for (std::size_t i = 0; i < mesh.pieces.size(); ++i) {
      auto hull = std::make_unique<btConvexHullShape>();
      const auto& corners_of = i < mesh.hull_corners.size() && !mesh.hull_corners[i].empty() ? mesh.hull_corners[i] : mesh.pieces[i];
      for (std::uint32_t v : corners_of) hull->addPoint(mm(pose * mesh.vertices[v]) - centre, false);
      hull->recalcLocalAabb();
      hull->initializePolyhedralFeatures();  // whole contact patches at once (with SAT below)
      shape->addChildShape(btTransform::getIdentity(), hull.get());
      hulls.push_back(std::move(hull));
    }
    const double mass = volume * 1e-3;  // 1 g/cm^3: only the ratios matter
    btVector3 inertia;
    shape->calculateLocalInertia(mass, inertia);
    bodies[p] = std::make_unique<btRigidBody>(btRigidBody::btRigidBodyConstructionInfo(mass, nullptr, shape.get(), inertia));
    bodies[p]->setWorldTransform(btTransform(btQuaternion::getIdentity(), centre));
    bodies[p]->setActivationState(DISABLE_DEACTIVATION);
    world.addRigidBody(bodies[p].get());
    std::array<btVector3, 8> box;
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d corner = mesh.bounds.corner(static_cast<Eigen::AlignedBox3d::CornerType>(k));
      box[k] = mm(pose * corner) - centre;
    }
    corners.push_back(box);
    centres.push_back(centre);
    order.push_back(p);
    shapes.push_back(std::move(shape));
  }
  std::vector<std::unique_ptr<btFixedConstraint>> joints;
  const auto fastened = fastened_among(c.product->product, c.parts);
  for (std::size_t k = 0; k < fastened.size(); ++k) {
    if (!fastened[k]) continue;
    const auto& connection = c.product->product.connections()[k];
    btRigidBody& a = *bodies[connection.part1];
    btRigidBody& b = *bodies[connection.part2];
    // Frames where they stand now: the joint keeps them so.
    joints.push_back(std::make_unique<btFixedConstraint>(a, b, btTransform::getIdentity(),
                                                         b.getWorldTransform().inverse() * a.getWorldTransform()));
    world.addConstraint(joints.back().get(), true);
  }
  for (int step = 0; step < 120; ++step) world.stepSimulation(1.0 / 240, 0);

  double moved = 0;  // mm, the most any corner went
  for (std::size_t i = 0; i < order.size(); ++i) {
    for (const btVector3& corner : corners[i]) {
      moved = std::max(moved, static_cast<double>((bodies[order[i]]->getWorldTransform() * corner - (corner + centres[i])).length()));
    }
  }
  for (auto& joint : joints) world.removeConstraint(joint.get());
  for (twin::PartIndex p : order) world.removeRigidBody(bodies[p].get());
  world.removeRigidBody(&table);
  return moved <= 1.0;
}

// The blocks of a stack, from their meshes' boxes: does the whole stack stand upright?
// Empty where a centre of mass lies within 0.5 mm of an edge of the face it stands on.
std::optional<bool> stack_stands(const twin::LoadedProduct& stack) {
  const auto& parts = stack.product.parts();
  const auto& connections = stack.product.connections();
  bool stands = true;
  for (std::size_t k = 0; k < parts.size(); ++k) {  // the face under block k (k = 0: the station's)
    bool glued = false;
    for (const auto& c : connections) glued |= k > 0 && c.part2 == k && c.part1 == k - 1 && c.joint.fastens();
    if (glued) continue;
    double mass = 0, moment_x = 0;
    for (std::size_t j = k; j < parts.size(); ++j) {
      const auto& box = stack.meshes[j]->bounds;
      mass += box.volume();
      moment_x += box.volume() * box.center().x();
    }
    const double x = moment_x / mass;
    const auto& above = stack.meshes[k]->bounds;
    const auto& below = k > 0 ? stack.meshes[k - 1]->bounds : above;
    const double lo = std::max(below.min().x(), above.min().x()), hi = std::min(below.max().x(), above.max().x());
    if (std::abs(x - lo) < 5e-4 || std::abs(x - hi) < 5e-4) return std::nullopt;
    if (lo >= hi || x < lo || x > hi) stands = false;
  }
  return stands;
}

struct Cases {
  std::deque<twin::LoadedProduct> products;  // a deque: the cases point into it as it grows
  std::vector<Case> cases;
};

const Cases& stacks() {
  static const Cases made = [] {
    Cases out;
    for (std::uint32_t seed = 1; out.products.size() < 400 && seed < 2000; ++seed) {
      auto generated = test::stacked_blocks(seed);
      const auto truth = stack_stands(generated.product);
      if (!truth) continue;
      out.products.push_back(std::move(generated.product));
      std::vector<twin::PartIndex> all(out.products.back().product.parts().size());
      for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
      out.cases.push_back({&out.products.back(), all, *truth});
    }
    return out;
  }();
  return made;
}

const Cases& posts() {
  static const Cases made = [] {
    Cases out;
    for (std::uint32_t seed = 1; out.products.size() < 100; ++seed) {
      auto generated = test::posts_and_beams(seed);
      if (generated.expect != test::Expect::buildable) continue;
      out.products.push_back(std::move(generated.product));
      std::vector<twin::PartIndex> base_and_posts;
      for (std::size_t i = 0; i < out.products.back().product.parts().size(); ++i) {
        const std::string& name = out.products.back().product.parts()[i].name;
        if (name == "base" || name.rfind("post", 0) == 0) base_and_posts.push_back(i);
      }
      out.cases.push_back({&out.products.back(), base_and_posts, true});
    }
    return out;
  }();
  return made;
}

const Cases& cranfield() {
  static const Cases made = [] {
    Cases out;
    sim::MeshCache cache;
    out.products.push_back(twin::load_product(std::filesystem::path(PRODUCTS_DIR) / "cranfield/cranfield.aml", cache));
    auto sequence = twin::make_sequence_planner("search");
    auto path = twin::make_path_planner("linear");
    const twin::Plan plan = twin::plan_assembly(out.products[0], *sequence, *path);
    std::vector<twin::PartIndex> placed;
    for (const auto& step : plan.steps) {
      placed.push_back(step.part);
      out.cases.push_back({&out.products[0], placed, true});
    }
    return out;
  }();
  return made;
}

template <bool Dynamic>
void run(benchmark::State& state, const Cases& (*make)()) {
  const Cases& cases = make();
  std::size_t falls_wrongly = 0, stands_wrongly = 0;
  for (auto _ : state) {
    falls_wrongly = stands_wrongly = 0;
    for (std::size_t i = 0; i < cases.cases.size(); ++i) {
      const Case& c = cases.cases[i];
      bool stands;
      if constexpr (Dynamic) {
        stands = stands_dynamic(c, static_cast<int>(state.range(0)));
      } else {
        // A fresh analysis per state: its contacts found and nothing remembered.
        stands = stands_static(twin::StabilityAnalysis(*c.product, {0.5, 0.0, 8, 5e-4}), c);
      }
      falls_wrongly += c.stands && !stands;
      stands_wrongly += !c.stands && stands;
    }
  }
  state.counters["states"] = static_cast<double>(cases.cases.size());
  state.counters["standing"] =
      static_cast<double>(std::count_if(cases.cases.begin(), cases.cases.end(), [](const Case& c) { return c.stands; }));
  state.counters["falls_wrongly"] = static_cast<double>(falls_wrongly);
  state.counters["stands_wrongly"] = static_cast<double>(stands_wrongly);
  state.counters["per_state"] = benchmark::Counter(static_cast<double>(cases.cases.size()),
                                                   benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_Static(benchmark::State& state, const Cases& (*make)()) { run<false>(state, make); }
void BM_Bullet(benchmark::State& state, const Cases& (*make)()) { run<true>(state, make); }

}  // namespace

BENCHMARK_CAPTURE(BM_Static, stacks, stacks)->Iterations(1)->Unit(benchmark::kMillisecond);
// Bullet's solver iterations (10 its default): stacks stand better with more, and cost more.
BENCHMARK_CAPTURE(BM_Bullet, stacks, stacks)->Arg(10)->Arg(50)->Arg(200)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Static, posts, posts)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Bullet, posts, posts)->Arg(10)->Arg(200)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Static, cranfield, cranfield)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Bullet, cranfield, cranfield)->Arg(10)->Arg(200)->Iterations(1)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
