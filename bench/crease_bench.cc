// The keyframe crease check (issue 10 item 1): which ORB pyramid level LSD should run on. For
// levels 0, 1, 2 (1, 1/1.2, 1/1.44 of the image): the time of LSD alone and of the whole check
// (labels, projection, LSD, matching) per keyframe, and the check's accuracy at the ground-truth
// poses as counters: creases confirmed per visible crease (`confirmed_per_visible`), median
// over keyframes of the median edge distance (`median_edge_px`, level-0 pixels), visible
// creases and LSD segments per keyframe.
//
//   PLANELOC_CREASE_BENCH_DIR=DIR build/bin/crease_bench --benchmark_format=json
// DIR holds `sim/` (planeloc sim) and `planes.json` (map build + map planes on it), as
// scripts/bench_wrong_map.sh leaves them. Without it: the simulator's `tiny` preset, seed 3,
// rendered to a temporary folder, with its ground-truth planes (planes_gt.json).
// Every 5th frame (at most 40) is a "keyframe"; the pyramids are built before timing.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <vector>

#include "planeloc/features/orb_extractor.h"
#include "planeloc/io/kitti_sequence.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/prior/crease_check.h"
#include "planeloc/sim/simulator.h"

namespace planeloc {
namespace {

struct Data {
  StereoCamera camera;
  PlaneMap planes;
  std::vector<std::vector<cv::Mat>> pyramids;  // left images, levels 0..2
  std::vector<Rigid3d> cam_from_world;         // ground truth
};

const Data& Load() {
  static std::unique_ptr<Data> data;
  if (data) return *data;
  data = std::make_unique<Data>();
  std::filesystem::path sequence_dir, planes_path;
  if (const char* dir = std::getenv("PLANELOC_CREASE_BENCH_DIR")) {
    sequence_dir = std::filesystem::path(dir) / "sim" / "sequences" / "00";
    planes_path = std::filesystem::path(dir) / "planes.json";
  } else {
    sim::SimOptions options = sim::SimOptions::FromPreset("tiny");
    options.seed = 3;
    options.show_progress = false;
    const auto out = std::filesystem::temp_directory_path() / "planeloc_crease_bench_tiny3";
    const sim::SimResult result = sim::GenerateSequence(options, out, /*force=*/true);
    sequence_dir = result.sequence_dir;
    planes_path = result.planes_path;
  }
  data->planes = ReadPlaneMap(planes_path);
  const KittiSequence sequence = KittiSequence::Open(sequence_dir);
  data->camera = sequence.camera();
  OrbOptions orb;
  orb.num_levels = 3;
  const OrbExtractor extractor(orb);
  for (std::size_t i = 0; i < sequence.size() && data->pyramids.size() < 40; i += 5) {
    data->pyramids.push_back(extractor.BuildPyramid(sequence.LoadStereoPair(i).left));
    data->cam_from_world.push_back(sequence.ground_truth()->at(i).Inverse());
  }
  return *data;
}

void BM_LsdAtLevel(benchmark::State& state) {
  const Data& data = Load();
  const int level = static_cast<int>(state.range(0));
  std::size_t k = 0, segments = 0, calls = 0;
  for (auto _ : state) {
    const auto& image = data.pyramids[k++ % data.pyramids.size()][level];
    segments += DetectSegmentsAtLevel(image, data.camera.width, LsdOptions()).size();
    ++calls;
  }
  state.counters["segments"] = static_cast<double>(segments) / calls;
}
BENCHMARK(BM_LsdAtLevel)
    ->DenseRange(0, 2)
    ->ArgName("level")
    ->Iterations(40)
    ->Unit(benchmark::kMillisecond);

void BM_CreaseCheckAtLevel(benchmark::State& state) {
  const Data& data = Load();
  CreaseCheckOptions options;
  options.lsd_level = static_cast<int>(state.range(0));
  CreaseChecker checker(data.planes, options);
  std::vector<double> medians;
  double visible = 0, confirmed = 0, segments = 0;
  std::size_t k = 0;
  for (auto _ : state) {
    const std::size_t i = k++ % data.pyramids.size();
    const CreaseCheckStats stats =
        checker.CheckKeyframe(static_cast<int>(i), data.cam_from_world[i], data.camera,
                              data.pyramids[i][options.lsd_level]);
    visible += stats.visible_creases;
    confirmed += stats.confirmed_creases;
    segments += stats.lsd_segments;
    if (stats.median_edge_px) medians.push_back(*stats.median_edge_px);
  }
  std::sort(medians.begin(), medians.end());
  state.counters["keyframes"] = static_cast<double>(data.pyramids.size());
  state.counters["visible_creases"] = visible / k;
  state.counters["confirmed_per_visible"] = visible > 0 ? confirmed / visible : 0.0;
  state.counters["median_edge_px"] = medians.empty() ? -1.0 : medians[medians.size() / 2];
  state.counters["segments"] = segments / k;
}
BENCHMARK(BM_CreaseCheckAtLevel)
    ->DenseRange(0, 2)
    ->ArgName("level")
    ->Iterations(40)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace planeloc

BENCHMARK_MAIN();
