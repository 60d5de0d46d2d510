// Planning speed: Cranfield, the Lego tower, generated walls (10 blocks wide) and towers
// (one block wide) of 10, 100, 1000 blocks, for each sequence planner; swept collision
// checks per second. Run by hand (Release):
//   build/release/tests/bench_planning
// Figures and the command are recorded in docs/performance.md.

#include <fstream>

#include <benchmark/benchmark.h>
#include <unistd.h>

#include "tests/support/wall_product.hpp"
#include "twin/planning/assembly_planner.hpp"

namespace {

std::filesystem::path wall_dir(int columns, int rows) {
  const auto dir = std::filesystem::temp_directory_path() / ("bench-wall-" + std::to_string(::getpid()) + "-" +
                                                             std::to_string(columns) + "x" + std::to_string(rows));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "block.obj") << test::wall_block_obj();
  std::ofstream(dir / "wall.aml") << test::wall_aml(columns, rows, "block.obj");
  return dir / "wall.aml";
}

void plan_file(benchmark::State& state, const std::filesystem::path& file, const std::string& sequence) {
  sim::MeshCache cache;
  const twin::LoadedProduct loaded = twin::load_product(file, cache);
  std::size_t trajectories = 0;
  for (auto _ : state) {
    auto s = twin::make_sequence_planner(sequence);
    auto p = twin::make_path_planner("linear");
    const twin::Plan plan = twin::plan_assembly(loaded, *s, *p);
    if (!plan.complete) state.SkipWithError("plan incomplete");
    trajectories = plan.trajectories_simulated;
  }
  state.counters["parts"] = static_cast<double>(loaded.product.parts().size());
  state.counters["trajectories"] = static_cast<double>(trajectories);
}

void BM_Cranfield(benchmark::State& state, const std::string& sequence) {
  plan_file(state, std::filesystem::path(PRODUCTS_DIR) / "cranfield/cranfield.aml", sequence);
}
void BM_LegoTower(benchmark::State& state, const std::string& sequence) {
  plan_file(state, std::filesystem::path(PRODUCTS_DIR) / "lego-tower/lego-tower.aml", sequence);
}
void BM_Wall(benchmark::State& state, const std::string& sequence) {
  const int parts = static_cast<int>(state.range(0));
  const int columns = parts >= 100 ? 10 : 5;
  const auto file = wall_dir(columns, parts / columns);
  plan_file(state, file, sequence);
  std::filesystem::remove_all(file.parent_path());
}

void BM_Tower(benchmark::State& state, const std::string& sequence) {
  const int parts = static_cast<int>(state.range(0));
  const auto file = wall_dir(1, parts);
  plan_file(state, file, sequence);
  std::filesystem::remove_all(file.parent_path());
}

// One swept check: a Cranfield peg down through its hole, 200 mm.
void BM_PegSweep(benchmark::State& state) {
  sim::MeshCache cache;
  sim::CollisionWorld world;
  const auto products = std::filesystem::path(PRODUCTS_DIR);
  world.add_static_mesh("back", cache.get(products / "cranfield/meshes/faceplate.obj"), sim::Pose::Identity());
  sim::MovingBody peg;
  peg.add_mesh("part", *cache.get(products / "cranfield/meshes/round_peg.obj"), sim::Pose::Identity(), 5e-5);
  sim::Pose from = sim::Pose::Identity(), to = sim::Pose::Identity();
  from.translation() = Eigen::Vector3d(0, 0.2, 0.014);
  to.translation() = Eigen::Vector3d(0, 0, 0.014);
  const std::size_t before = world.checks();
  for (auto _ : state) benchmark::DoNotOptimize(world.sweep(peg, from, to));
  state.counters["penetration_tests/sweep"] =
      static_cast<double>(world.checks() - before) / static_cast<double>(state.iterations());
  state.SetItemsProcessed(state.iterations());
}

}  // namespace

BENCHMARK_CAPTURE(BM_Cranfield, paper, std::string("paper"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Cranfield, search, std::string("search"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LegoTower, paper, std::string("paper"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LegoTower, search, std::string("search"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Wall, paper, std::string("paper"))->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Wall, search, std::string("search"))->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Tower, paper, std::string("paper"))->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Tower, search, std::string("search"))->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PegSweep)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
