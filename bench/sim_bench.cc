// Simulator speed: one camera view (1226x370, 2x2 supersampling), one LiDAR scan (64 x 2250
// beams) and the one-off set-up (textures, town), on the kitti07-like world. A full frame is two
// views and one scan; docs/bench-sim.md extrapolates to the 1 101-frame preset.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <ctime>
#include <memory>

#include "planeloc/sim/raycast.h"
#include "planeloc/sim/render.h"
#include "planeloc/sim/shading.h"
#include "planeloc/sim/simulator.h"
#include "planeloc/sim/texture.h"
#include "planeloc/util/temp_dir.h"

namespace {

using namespace planeloc;
using namespace planeloc::sim;

struct Fixture {
  Scenario scenario;
  TextureBank bank;
  std::unique_ptr<Scene> scene;
  std::unique_ptr<Shader> shader;
  explicit Fixture(Lighting lighting) {
    SimOptions options = SimOptions::FromPreset("kitti07-like");
    options.lighting = lighting;
    scenario = BuildScenario(options);
    bank = TextureBank::Procedural(7);
    scene = std::make_unique<Scene>(scenario.world);
    shader = std::make_unique<Shader>(scenario.world, bank);
  }
};

Fixture& Get(Lighting lighting) {
  static Fixture constant(Lighting::kConstant);
  static Fixture changing(Lighting::kChanging);
  return lighting == Lighting::kConstant ? constant : changing;
}

// Frames spread over the loop (straights, turns) so the cost is representative.
const Rigid3d& PoseAt(const Fixture& f, int i) {
  const auto& poses = f.scenario.world_from_cam;
  return poses[(static_cast<std::size_t>(i) * 137u) % poses.size()];
}

void BM_RenderView(benchmark::State& state) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, state.range(0));
  const Lighting lighting = state.range(1) ? Lighting::kChanging : Lighting::kConstant;
  Fixture& f = Get(lighting);
  int i = 0;
  const std::clock_t cpu_start = std::clock();
  for (auto _ : state) {
    const FrameLighting light = LightingForFrame(lighting, 1, i);
    benchmark::DoNotOptimize(
        RenderView(*f.scene, *f.shader, Kitti07Camera(), PoseAt(f, i), light, 1u + i));
    ++i;
  }
  state.counters["process_cpu_ms"] =
      1e3 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC / state.iterations();
}
BENCHMARK(BM_RenderView)
    ->Args({1, 0})
    ->Args({1, 1})
    ->Args({2, 0})
    ->Args({2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_LidarScan(benchmark::State& state) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, state.range(0));
  Fixture& f = Get(Lighting::kConstant);
  int i = 0;
  std::size_t points = 0;
  const std::clock_t cpu_start = std::clock();
  for (auto _ : state) {
    const auto scan = ScanLidar(*f.scene, *f.shader, PoseAt(f, i) * Kitti07CamFromVelo(), 1u + i);
    points += scan.points.size();
    ++i;
  }
  state.counters["points"] = static_cast<double>(points) / state.iterations();
  state.counters["process_cpu_ms"] =
      1e3 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC / state.iterations();
}
BENCHMARK(BM_LidarScan)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Setup(benchmark::State& state) {
  for (auto _ : state) {
    Scenario scenario = BuildScenario(SimOptions::FromPreset("kitti07-like"));
    TextureBank bank = TextureBank::Procedural(7);
    Scene scene(scenario.world);
    benchmark::DoNotOptimize(scene.node_count());
  }
}
BENCHMARK(BM_Setup)->Unit(benchmark::kMillisecond)->Iterations(1);

// End to end: GenerateSequence of the first N kitti07-like frames (set-up, two views, one scan,
// PNG and .bin writing) with 1 or 2 threads; per-frame time = (total - set-up) / N.
void BM_GenerateKitti07Like(benchmark::State& state) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, state.range(0));
  SimOptions options = SimOptions::FromPreset("kitti07-like");
  options.frames = static_cast<int>(state.range(1));
  options.show_progress = false;
  const std::clock_t cpu_start = std::clock();  // process CPU time: all threads
  for (auto _ : state) {
    TempDir dir("planeloc-sim-bench");
    benchmark::DoNotOptimize(GenerateSequence(options, dir.path()).frames);
  }
  const double cpu = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  state.counters["frames"] = static_cast<double>(state.range(1));
  state.counters["process_cpu_s"] = cpu / static_cast<double>(state.iterations());
}
BENCHMARK(BM_GenerateKitti07Like)
    ->Args({2, 40})
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
