// Density benchmarks (issue 17): `map planes` on one raw Velodyne scan (~120 k points, KITTI-00
// 000094 from ../shared/data) with and without the voxel filter and the neighbour cap, against the
// same scan voxelized as `map build` writes it; and a large binary .pcd (tens of millions of
// points) read with the voxel filter in bounded memory. Results in docs/bench-map.md.
//   build/bin/map_density_bench --benchmark_counters_tabular=true
//   build/bin/map_density_bench --benchmark_filter=LargePcd  (alone, so that max_rss_mb is this
//   benchmark's peak; PLANELOC_BENCH_LARGE_POINTS sets the size, default 20 000 000)
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include "planeloc/io/kitti_sequence.h"
#include "planeloc/io/point_cloud.h"
#include "planeloc/map/map_builder.h"
#include "planeloc/map/map_planes.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

std::filesystem::path ScanPath() {
  const char* env = std::getenv("PLANELOC_SHARED_DATA");
  const std::filesystem::path root =
      env ? std::filesystem::path(env)
          : std::filesystem::path(PLANELOC_SOURCE_DIR) / ".." / "shared" / "data";
  return root / "kitti00-velodyne" / "000094.bin";
}

double MaxRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // kB on Linux
}

// Arguments: mode (0 raw scan, 1 the scan voxelized by `map build`'s accumulator at 0.10 m),
// voxel filter of `map planes` in mm (-1 = default sigma / 5), neighbour cap (0 = none).
void BM_MapPlanesScan(benchmark::State& state) {
  if (!std::filesystem::exists(ScanPath())) {
    state.SkipWithError("../shared/data/kitti00-velodyne/000094.bin missing");
    return;
  }
  PointCloud map;
  map.points = ReadVelodyneScan(ScanPath()).points;
  if (state.range(0) == 1) {
    MapBuildOptions build;
    build.show_progress = false;
    MapAccumulator accumulator(build);
    accumulator.AddScan(map.points, Rigid3d::Identity());
    map = accumulator.Finish();
  }
  MapPlanesOptions options;
  options.voxel_size = state.range(1) < 0 ? -1.0 : static_cast<double>(state.range(1)) / 1000.0;
  options.tensor_voting.max_neighbors = static_cast<int>(state.range(2));
  options.plane_extraction.up = Eigen::Vector3d::UnitZ();
  MapPlanesOutput output;
  for (auto _ : state) {
    output = RunMapPlanes(map, options);
    benchmark::DoNotOptimize(output.points.data());
  }
  const double hood = static_cast<double>(output.voting.neighborhoods.indices.size());
  state.counters["input_points"] = static_cast<double>(map.size());
  state.counters["voted_points"] = static_cast<double>(output.points.size());
  state.counters["mean_neighbours"] = hood / static_cast<double>(output.points.size());
  state.counters["planes"] = static_cast<double>(output.extraction.plane_map.planes.size());
  state.counters["voting_s"] = output.voting_seconds;
  state.counters["extraction_s"] = output.extraction_seconds;
}

BENCHMARK(BM_MapPlanesScan)
    ->Args({0, 0, 0})     // raw scan, no filter, no cap: before issue 17
    ->Args({0, 0, 512})   // raw scan, cap only
    ->Args({0, -1, 512})  // raw scan, default: 0.1 m voxels, cap 512
    ->Args({1, 0, 512})   // the scan as `map build` writes it (0.1 m voxels), no second filter
    ->Args({1, -1, 512})  // the same with the default filter (what `map planes` now does)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);

// A street 400 m long: road (16 m) and two 10 m facades, points drawn uniformly on them, written
// as a binary .pcd with x y z intensity (16 bytes a point) without holding them in memory.
std::filesystem::path WriteLargePcd(const std::filesystem::path& dir, std::size_t points) {
  const auto path = dir / "large.pcd";
  std::ofstream out(path, std::ios::binary);
  out << "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\n"
      << "COUNT 1 1 1 1\nWIDTH " << points << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS "
      << points << "\nDATA binary\n";
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> along(0.f, 400.f), unit(0.f, 1.f);
  std::normal_distribution<float> noise(0.f, 0.02f);
  std::vector<float> chunk;
  for (std::size_t i = 0; i < points; ++i) {
    const float s = along(rng), t = unit(rng);
    const int surface = static_cast<int>(unit(rng) * 36.f);  // 16 road, 10 + 10 facade metres
    float x = s, y, z;
    if (surface < 16) {
      y = -8.f + 16.f * t, z = 0.f;
    } else {
      y = surface < 26 ? -8.f : 8.f, z = 10.f * t;
    }
    chunk.insert(chunk.end(), {x + noise(rng), y + noise(rng), z + noise(rng), 1.f});
    if (chunk.size() >= (1u << 20) || i + 1 == points) {
      out.write(reinterpret_cast<const char*>(chunk.data()),
                static_cast<std::streamsize>(chunk.size() * sizeof(float)));
      chunk.clear();
    }
  }
  return path;
}

void BM_ReadLargePcdWithVoxelFilter(benchmark::State& state) {
  const char* env = std::getenv("PLANELOC_BENCH_LARGE_POINTS");
  const std::size_t points = env ? std::strtoull(env, nullptr, 10) : 20'000'000;
  TempDir dir("planeloc-bench-large");
  const auto path = WriteLargePcd(dir.path(), points);
  const double rss_before = MaxRssMb();
  PointCloudReadOptions options;
  options.voxel_size = 0.1;
  PointCloud cloud;
  for (auto _ : state) {
    cloud = ReadPointCloud(path, options);
    benchmark::DoNotOptimize(cloud.points.data());
  }
  state.counters["file_points"] = static_cast<double>(cloud.source_points);
  state.counters["voxels"] = static_cast<double>(cloud.size());
  state.counters["file_mb"] = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
  state.counters["max_rss_mb"] = MaxRssMb();
  state.counters["rss_before_mb"] = rss_before;
}

BENCHMARK(BM_ReadLargePcdWithVoxelFilter)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace
}  // namespace planeloc

BENCHMARK_MAIN();
