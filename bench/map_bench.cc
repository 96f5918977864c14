// Map benchmarks (issue 4): tensor-voting normals vs Open3D EstimateNormals (PCA, same radius
// neighbourhood) on a synthetic street map with 1 cm and 3 cm noise — time and mean angle error,
// overall and within 0.3 m of a plane intersection — and plane extraction time.
//
// Map size: PLANELOC_BENCH_MAP_POINTS (default 1 000 000) points; results in docs/bench-map.md.
//   build-map/bin/map_bench --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>
#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>

#include <cmath>
#include <cstdlib>
#include <map>
#include <numbers>

#include "planeloc/map/neighborhoods.h"
#include "planeloc/map/plane_extraction.h"
#include "planeloc/map/synthetic_scene_for_test.h"
#include "planeloc/map/tensor_voting.h"

namespace planeloc {
namespace {

using testing::SceneBuilder;
using testing::SyntheticScene;

// A straight street: road (z = 0), facades on both sides (y = +-8, 8 m high), a parked car (box)
// and a tree crown (volumetric blob) every 20 m. Length chosen to give about `target` points at 10
// cm spacing.
SyntheticScene Street(std::size_t target, double noise) {
  const double per_metre = (16.0 + 2 * 8.0) / (0.1 * 0.1);  // road + two facades
  const double length = std::max(20.0, static_cast<double>(target) / per_metre / 1.05);
  SceneBuilder builder(0.1, noise, 17);
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  builder.Rectangle({0, -8, 0}, x, length, y, 16.0, true);
  builder.Rectangle({0, -8, 0}, x, length, z, 8.0, true);
  builder.Rectangle({0, 8, 0}, x, length, z, 8.0, true);
  for (double s = 10.0; s + 5.0 < length; s += 20.0) {
    builder.Box({s, -6.5, 0.2}, {s + 4.5, -4.7, 1.6});
    builder.Blob({s + 10.0, 5.5, 4.0}, 1.2, 1500);
  }
  return builder.scene();
}

struct Scenes {
  std::map<int, SyntheticScene> by_noise_mm;
  const SyntheticScene& Get(int noise_mm) {
    auto it = by_noise_mm.find(noise_mm);
    if (it == by_noise_mm.end()) {
      const char* env = std::getenv("PLANELOC_BENCH_MAP_POINTS");
      const std::size_t target = env ? std::strtoull(env, nullptr, 10) : 1'000'000;
      it = by_noise_mm.emplace(noise_mm, Street(target, noise_mm / 1000.0)).first;
    }
    return it->second;
  }
};
Scenes& SharedScenes() {
  static Scenes scenes;
  return scenes;
}

// Mean angle (degrees) to the GT normal over GT-plane points, all and within 0.3 m of a crease
// (road-facade line: a road point near |y| = 8 or a facade point near z = 0).
void AngleCounters(benchmark::State& state, const SyntheticScene& scene,
                   const std::vector<Eigen::Vector3d>& normals) {
  double all = 0.0, crease = 0.0;
  std::size_t n_all = 0, n_crease = 0;
  for (std::size_t i = 0; i < scene.points.size(); ++i) {
    const int label = scene.gt_label[i];
    if (label < 0) continue;
    const double cosine = std::min(1.0, std::abs(normals[i].dot(scene.gt_planes[label].normal)));
    const double angle = std::acos(cosine) * 180.0 / std::numbers::pi;
    all += angle;
    ++n_all;
    const Eigen::Vector3d& p = scene.points[i];
    const double to_crease = label == 0 ? 8.0 - std::abs(p.y()) : p.z();
    if (to_crease < 0.3) {
      crease += angle;
      ++n_crease;
    }
  }
  state.counters["points"] = static_cast<double>(scene.points.size());
  state.counters["mean_err_deg"] = all / static_cast<double>(n_all);
  state.counters["crease_err_deg"] = crease / static_cast<double>(n_crease);
}

void BM_TensorVotingNormals(benchmark::State& state) {
  const SyntheticScene& scene = SharedScenes().Get(static_cast<int>(state.range(0)) * 10);
  TensorVotingOptions options;
  options.stick_passes = static_cast<int>(state.range(1));
  TensorVotingResult result;
  for (auto _ : state) {
    result = RunTensorVoting(scene.points, options);
    benchmark::DoNotOptimize(result.normals.data());
  }
  AngleCounters(state, scene, result.normals);
  state.counters["mean_neighbours"] =
      static_cast<double>(result.neighborhoods.indices.size()) / result.size();
}

// The same map already in Morton order, as `planeloc map build` writes it: RunTensorVoting then
// votes in place (no sorted copy, one neighbour search instead of two).
void BM_TensorVotingNormalsMortonInput(benchmark::State& state) {
  const SyntheticScene& input = SharedScenes().Get(static_cast<int>(state.range(0)) * 10);
  SyntheticScene scene = input;
  const std::vector<std::int32_t> order = MortonOrder(input.points, TensorVotingOptions().radius());
  for (std::size_t k = 0; k < order.size(); ++k) {
    scene.points[k] = input.points[order[k]];
    scene.gt_label[k] = input.gt_label[order[k]];
  }
  TensorVotingResult result;
  for (auto _ : state) {
    result = RunTensorVoting(scene.points, TensorVotingOptions());
    benchmark::DoNotOptimize(result.normals.data());
  }
  AngleCounters(state, scene, result.normals);
}

void BM_Open3dEstimateNormals(benchmark::State& state) {
  const SyntheticScene& scene = SharedScenes().Get(static_cast<int>(state.range(0)) * 10);
  std::vector<Eigen::Vector3d> normals;
  for (auto _ : state) {
    open3d::geometry::PointCloud cloud;
    cloud.points_ = scene.points;
    cloud.EstimateNormals(open3d::geometry::KDTreeSearchParamRadius(TensorVotingOptions().radius()),
                          true);
    normals = std::move(cloud.normals_);
    benchmark::DoNotOptimize(normals.data());
  }
  AngleCounters(state, scene, normals);
}

void BM_PlaneExtraction(benchmark::State& state) {
  const SyntheticScene& scene = SharedScenes().Get(static_cast<int>(state.range(0)) * 10);
  const TensorVotingResult voting = RunTensorVoting(scene.points, TensorVotingOptions());
  PlaneExtractionOptions options;
  options.up = Eigen::Vector3d::UnitZ();
  PlaneExtractionResult result;
  for (auto _ : state) {
    result = ExtractPlanes(scene.points, voting, options);
    benchmark::DoNotOptimize(result.point_plane.data());
  }
  state.counters["planes"] = static_cast<double>(result.plane_map.planes.size());
  state.counters["points"] = static_cast<double>(scene.points.size());
}

// Arguments: noise in centimetres (, stick passes).
BENCHMARK(BM_TensorVotingNormals)
    ->ArgsProduct({{1, 3}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->Iterations(1);
BENCHMARK(BM_TensorVotingNormalsMortonInput)
    ->Arg(1)
    ->Arg(3)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->Iterations(1);
// Process CPU time (all threads) is the fair comparison on a shared machine; wall time is also
// reported.
BENCHMARK(BM_Open3dEstimateNormals)
    ->Arg(1)
    ->Arg(3)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->Iterations(1);
BENCHMARK(BM_PlaneExtraction)
    ->Arg(3)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->Iterations(1);

}  // namespace
}  // namespace planeloc

BENCHMARK_MAIN();
