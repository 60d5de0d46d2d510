// Planning speed: Cranfield, the Lego tower, generated walls (10 blocks wide) and towers
// (one block wide) of 10, 100, 1000 blocks, for each sequence planner; swept collision
// checks per second. Run by hand (Release):
//   build/release/tests/bench_planning
// Figures and the command are recorded in docs/performance.md.

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>
#include <fstream>
#include <sstream>

#include <benchmark/benchmark.h>
#include <unistd.h>

#include "tests/support/meshes.hpp"
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

// `sequence`: "paper" or "search"; "search, no margins": without insertion margins;
// "search, unverified": without the plan's independent replay (plan_verifier.hpp).
void plan_file(benchmark::State& state, const std::filesystem::path& file, std::string sequence) {
  sim::MeshCache cache;
  const twin::LoadedProduct loaded = twin::load_product(file, cache);
  twin::PlannerOptions options;
  if (sequence == "search, no margins") {
    sequence = "search";
    options.margin_reach = 0;
  }
  if (sequence == "search, unverified") {
    sequence = "search";
    options.verify = false;
  }
  std::size_t trajectories = 0;
  for (auto _ : state) {
    auto s = twin::make_sequence_planner(sequence);
    auto p = twin::make_path_planner("linear");
    const twin::Plan plan = twin::plan_assembly(loaded, *s, *p, options);
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

// `rings` rings stacked, each its own one-piece concave mesh (a tube: 40 mm across, a 20 mm
// bore, 5 mm tall) of about `triangles` triangles: OBJ files in metres, or (`stl`) binary STL
// files in millimetres with every corner repeated per triangle, as CAD exports write them.
std::filesystem::path ring_stack(int triangles, int rings, bool stl) {
  const auto dir = std::filesystem::temp_directory_path() / ("bench-rings-" + std::to_string(::getpid()) + "-" +
                                                             std::to_string(triangles) + (stl ? "-stl" : ""));
  std::filesystem::create_directories(dir);
  const int segments = std::max(8, triangles / 8);
  std::ostringstream aml;
  aml << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<CAEXFile SchemaVersion=\"3.0\" FileName=\"rings.aml\" "
         "xmlns=\"http://www.dke.de/CAEX\"><InstanceHierarchy Name=\"Order\"><InternalElement Name=\"Rings\" ID=\"rings\">\n";
  std::ostringstream classes;
  for (int r = 0; r < rings; ++r) {
    const std::string name = "ring" + std::to_string(r);
    const double outer = 0.020 + r * 1e-5, inner = 0.010;  // each file its own content
    const sim::TriangleMesh ring = test::tube_mesh(segments, outer, inner, 0.005);
    const auto& v = ring.vertices;
    const auto& faces = ring.triangles;
    const std::string mesh = name + (stl ? ".stl" : ".obj");
    if (stl) {
      std::ofstream out(dir / mesh, std::ios::binary);
      const std::string header(80, ' ');
      out.write(header.data(), 80);
      const auto count = static_cast<std::uint32_t>(faces.size());
      out.write(reinterpret_cast<const char*>(&count), 4);
      for (const auto& f : faces) {
        float numbers[12] = {0, 0, 0};
        for (int c = 0; c < 3; ++c) {
          for (int k = 0; k < 3; ++k) numbers[3 + 3 * c + k] = static_cast<float>(v[f[c]][k] * 1000);
        }
        const std::uint16_t attributes = 0;
        out.write(reinterpret_cast<const char*>(numbers), sizeof numbers);
        out.write(reinterpret_cast<const char*>(&attributes), 2);
      }
    } else {
      std::ofstream obj(dir / mesh);
      obj << "o " << name << "\n";
      for (const auto& p : v) obj << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
      for (const auto& f : faces) obj << "f " << f[0] + 1 << ' ' << f[1] + 1 << ' ' << f[2] + 1 << '\n';
    }
    aml << "<InternalElement Name=\"" << name << "\" ID=\"" << name << "\" RefBaseSystemUnitPath=\"Lib/R" << r << "\"/>\n";
    if (r > 0) {
      aml << "<InternalLink Name=\"l" << r << "\" RefPartnerSideA=\"ring" << r - 1 << ":top\" RefPartnerSideB=\"" << name
          << ":bottom\"/>\n";
    }
    classes << "<SystemUnitClass Name=\"R" << r << "\">"
            << "<Attribute Name=\"bottom\" Unit=\"mm\"><DefaultValue>0,0,0</DefaultValue></Attribute>"
            << "<ExternalInterface Name=\"bottom\" ID=\"R" << r << "-bottom\"/>"
            << "<Attribute Name=\"top\" Unit=\"mm\"><DefaultValue>0,5,0</DefaultValue></Attribute>"
            << "<ExternalInterface Name=\"top\" ID=\"R" << r << "-top\"/>"
            << "<ExternalInterface Name=\"geometry\" ID=\"R" << r << "-geometry\" RefBaseClassPath=\"ExternalDataReference\">"
            << "<Attribute Name=\"refURI\"><Value>" << mesh << "</Value></Attribute>"
            << (stl ? "<Attribute Name=\"LengthUnit\"><Value>mm</Value></Attribute>" : "")
            << "</ExternalInterface></SystemUnitClass>\n";
  }
  aml << "</InternalElement></InstanceHierarchy><SystemUnitClassLib Name=\"Lib\">" << classes.str()
      << "</SystemUnitClassLib></CAEXFile>\n";
  std::ofstream(dir / "rings.aml") << aml.str();
  return dir / "rings.aml";
}

// What a twin pays for the ring stack: loading (every file parsed, or read back from the
// disk cache that an earlier order filled) and planning.
// `state.range(1)` rings; `stl`: unwelded binary STL in millimetres.
void BM_RingStack(benchmark::State& state, bool cached, bool stl = false) {
  const auto file = ring_stack(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), stl);
  const auto disk = file.parent_path() / "cache";
  if (cached) {
    sim::MeshCache earlier_order(disk);
    twin::load_product(file, earlier_order);
  }
  std::size_t triangles = 0;
  for (auto _ : state) {
    if (!cached) {
      state.PauseTiming();
      std::filesystem::remove_all(disk);
      state.ResumeTiming();
    }
    sim::MeshCache cache(disk);
    const twin::LoadedProduct loaded = twin::load_product(file, cache);
    auto s = twin::make_sequence_planner("search");
    auto p = twin::make_path_planner("linear");
    const twin::Plan plan = twin::plan_assembly(loaded, *s, *p);
    if (!plan.complete) state.SkipWithError("plan incomplete");
    triangles = loaded.meshes[0]->triangles.size();
  }
  state.counters["triangles/part"] = static_cast<double>(triangles);
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
BENCHMARK_CAPTURE(BM_Cranfield, search_no_margins, std::string("search, no margins"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Cranfield, search_unverified, std::string("search, unverified"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LegoTower, paper, std::string("paper"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LegoTower, search, std::string("search"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LegoTower, search_unverified, std::string("search, unverified"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Wall, paper, std::string("paper"))->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Wall, search, std::string("search"))->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Wall, search_no_margins, std::string("search, no margins"))->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Tower, paper, std::string("paper"))->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Tower, search, std::string("search"))->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PegSweep)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_RingStack, first, false)->Args({1000, 20})->Args({10000, 20})->Args({50000, 20})->Args({100000, 20})->Iterations(1)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RingStack, cached, true)->Args({1000, 20})->Args({10000, 20})->Args({50000, 20})->Args({100000, 20})->Iterations(1)
    ->Unit(benchmark::kMillisecond);
// A CAD export of 200k triangles per part: three rings as unwelded binary STL in millimetres.
BENCHMARK_CAPTURE(BM_RingStack, stl_first, false, true)->Args({200000, 3})->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RingStack, stl_cached, true, true)->Args({200000, 3})->Iterations(1)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
