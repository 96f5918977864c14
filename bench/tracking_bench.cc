// Tracking speed: frames per second of the whole tracker (features, tracking, local map, BA)
// on the real KITTI raw drive 0001 (108 frames) and on the simulator's `small` preset, with a
// per-stage breakdown as counters (ms per frame). Images are decoded before timing starts.
//
//   build/bin/tracking_bench                       # real frames (../shared/data)
//   PLANELOC_BENCH_SIM_SMALL=/tmp/small build/bin/tracking_bench   # + sim small (planeloc sim)
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <vector>

#include "planeloc/io/kitti_sequence.h"
#include "planeloc/pipeline/tracker.h"

namespace planeloc {
namespace {

std::filesystem::path SharedData() {
  if (const char* env = std::getenv("PLANELOC_SHARED_DATA")) return env;
  return std::filesystem::path(PLANELOC_SOURCE_DIR) / ".." / "shared" / "data";
}

struct LoadedSequence {
  StereoCamera camera;
  std::vector<StereoPair> pairs;
  std::vector<double> timestamps;
};

const LoadedSequence* Load(const std::filesystem::path& folder, std::size_t max_frames) {
  static std::map<std::string, LoadedSequence> cache;
  const auto it = cache.find(folder.string());
  if (it != cache.end()) return &it->second;
  if (!std::filesystem::exists(folder)) return nullptr;
  const KittiSequence sequence = KittiSequence::Open(folder);
  LoadedSequence loaded;
  loaded.camera = sequence.camera();
  for (std::size_t i = 0; i < std::min(max_frames, sequence.size()); ++i) {
    loaded.pairs.push_back(sequence.LoadStereoPair(i));
    loaded.timestamps.push_back(sequence.timestamp(i));
  }
  return &cache.emplace(folder.string(), std::move(loaded)).first->second;
}

// state.range(0): threads; state.range(1): 1 = deterministic (BA in line).
void TrackSequence(benchmark::State& state, const LoadedSequence* sequence) {
  if (sequence == nullptr) {
    state.SkipWithError("sequence not found");
    return;
  }
  TrackerOptions options;
  options.num_threads = static_cast<int>(state.range(0));
  options.deterministic = state.range(1) != 0;
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                              static_cast<std::size_t>(options.num_threads));
  double extract = 0, track = 0, local_map = 0, ba = 0;
  int frames = 0, lost = 0;
  for (auto _ : state) {
    Tracker tracker(sequence->camera, options);
    for (std::size_t i = 0; i < sequence->pairs.size(); ++i) {
      const TrackResult result =
          tracker.Track(sequence->pairs[i].left, sequence->pairs[i].right, sequence->timestamps[i]);
      extract += result.stats.ms_extract;
      track += result.stats.ms_track;
      local_map += result.stats.ms_local_map;
      ba += result.stats.ms_ba;
      lost += result.stats.state == TrackingState::kLost ? 1 : 0;
      ++frames;
    }
    tracker.Finish();
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
  state.counters["ms_extract"] = extract / frames;
  state.counters["ms_track"] = track / frames;
  state.counters["ms_local_map"] = local_map / frames;
  state.counters["ms_ba_inline"] = ba / frames;
  state.counters["lost"] = static_cast<double>(lost);
}

void BM_TrackKittiRaw0001(benchmark::State& state) {
  TrackSequence(state, Load(SharedData() / "kitti-raw-2011_09_26_drive_0001", 108));
}
BENCHMARK(BM_TrackKittiRaw0001)
    ->Args({2, 0})
    ->Args({2, 1})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->UseRealTime();

void BM_TrackSimSmall(benchmark::State& state) {
  const char* dir = std::getenv("PLANELOC_BENCH_SIM_SMALL");
  if (dir == nullptr) {
    state.SkipWithError("set PLANELOC_BENCH_SIM_SMALL to a `planeloc sim --preset small` output");
    return;
  }
  TrackSequence(state, Load(std::filesystem::path(dir) / "sequences" / "00", 300));
}
BENCHMARK(BM_TrackSimSmall)
    ->Args({2, 0})
    ->Args({2, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->UseRealTime();

}  // namespace
}  // namespace planeloc

BENCHMARK_MAIN();
