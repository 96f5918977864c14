// Feature extraction and stereo matching speed on one KITTI stereo pair (1242 x 375, drive
// 2011_09_26_0001 frame 0 from ../shared/data) or, when the data is absent, on a synthetic pair of
// the same size. Run: build/bin/features_bench [--benchmark_repetitions=N]
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <tbb/global_control.h>

#include <filesystem>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "planeloc/features/line_segments.h"
#include "planeloc/features/orb_extractor.h"
#include "planeloc/features/stereo_matcher.h"
#include "planeloc/features/test_images.h"

namespace planeloc {
namespace {

struct Pair {
  cv::Mat left, right;
  StereoCamera camera;
  bool real = false;
};

const Pair& TestPair() {
  static const Pair pair = [] {
    Pair p;
    const char* env = std::getenv("PLANELOC_SHARED_DATA");
    const std::filesystem::path root =
        env ? std::filesystem::path(env)
            : std::filesystem::path(PLANELOC_SOURCE_DIR) / ".." / "shared" / "data";
    const std::filesystem::path drive = root / "kitti-raw-2011_09_26_drive_0001";
    p.left = cv::imread((drive / "image_00/data/0000000000.png").string(), cv::IMREAD_GRAYSCALE);
    p.right = cv::imread((drive / "image_01/data/0000000000.png").string(), cv::IMREAD_GRAYSCALE);
    p.real = !p.left.empty() && !p.right.empty();
    if (!p.real) {  // synthetic stand-in: a textured plane 15 m away
      p.left = testing::RandomTexture(cv::Size(1242, 375), 1, 200.0, 128.0, 1.0);
      const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, -25.8, 0, 1, 0);
      cv::warpAffine(p.left, p.right, shift, p.left.size(), cv::INTER_LINEAR,
                     cv::BORDER_REFLECT_101);
    }
    // P_rect_00 / P_rect_01 of the drive's calib_cam_to_cam.txt.
    p.camera.fx = p.camera.fy = 721.5377;
    p.camera.cx = 609.5593;
    p.camera.cy = 172.854;
    p.camera.baseline = 387.5744 / 721.5377;
    p.camera.width = p.left.cols;
    p.camera.height = p.left.rows;
    return p;
  }();
  return pair;
}

// CPU time of the whole process (all threads), milliseconds: with several threads the "CPU"
// column of Google Benchmark counts the main thread only.
double ProcessCpuMs() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return (usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) * 1e3 +
         (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-3;
}

// Threads available to TBB: 0 = default (all cores).
void LimitThreads(int threads, std::unique_ptr<tbb::global_control>& control) {
  if (threads > 0) {
    control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    threads);
  }
}

void BM_OrbExtractOneImage(benchmark::State& state) {
  std::unique_ptr<tbb::global_control> control;
  LimitThreads(static_cast<int>(state.range(0)), control);
  const Pair& pair = TestPair();
  const OrbExtractor extractor{OrbOptions()};
  size_t features = 0;
  const double cpu_start = ProcessCpuMs();
  for (auto _ : state) {
    ImageFeatures result = extractor.Extract(pair.left);
    features = result.keypoints.size();
    benchmark::DoNotOptimize(result);
  }
  state.counters["features"] = static_cast<double>(features);
  state.counters["real_kitti"] = pair.real;
  state.counters["process_cpu_ms"] = (ProcessCpuMs() - cpu_start) / state.iterations();
}
BENCHMARK(BM_OrbExtractOneImage)->Arg(1)->Arg(2)->ArgName("threads")->Unit(benchmark::kMillisecond);

void BM_StereoExtractAndMatch(benchmark::State& state) {
  std::unique_ptr<tbb::global_control> control;
  LimitThreads(static_cast<int>(state.range(0)), control);
  const Pair& pair = TestPair();
  const OrbExtractor extractor{OrbOptions()};
  int matches = 0;
  const double cpu_start = ProcessCpuMs();
  for (auto _ : state) {
    StereoFeatures result =
        ExtractStereoFeatures(pair.left, pair.right, pair.camera, extractor, StereoMatchOptions());
    matches = result.num_stereo_matches();
    benchmark::DoNotOptimize(result);
  }
  state.counters["stereo_matches"] = matches;
  state.counters["real_kitti"] = pair.real;
  state.counters["process_cpu_ms"] = (ProcessCpuMs() - cpu_start) / state.iterations();
}
BENCHMARK(BM_StereoExtractAndMatch)
    ->Arg(1)
    ->Arg(2)
    ->ArgName("threads")
    ->Unit(benchmark::kMillisecond);

void BM_StereoMatchOnly(benchmark::State& state) {
  const Pair& pair = TestPair();
  const OrbExtractor extractor{OrbOptions()};
  const ImageFeatures left = extractor.Extract(pair.left);
  const ImageFeatures right = extractor.Extract(pair.right);
  int matches = 0;
  for (auto _ : state) {
    StereoFeatures result;
    result.left = left;  // shares the matrices: a cheap copy
    MatchStereo(right, pair.camera, extractor, StereoMatchOptions(), result);
    matches = result.num_stereo_matches();
    benchmark::DoNotOptimize(result);
  }
  state.counters["stereo_matches"] = matches;
}
BENCHMARK(BM_StereoMatchOnly)->Unit(benchmark::kMillisecond);

// Reference point: OpenCV's own ORB (clustered features) with the same budget and pyramid as
// OrbOptions (scripts/bench.sh divides BM_OrbExtractOneImage/threads:1 by this).
void BM_CvOrbDetectAndCompute(benchmark::State& state) {
  std::unique_ptr<tbb::global_control> control;
  LimitThreads(1, control);
  const Pair& pair = TestPair();
  const OrbOptions options;
  cv::Ptr<cv::ORB> orb = cv::ORB::create(
      options.num_features, static_cast<float>(options.scale_factor), options.num_levels);
  size_t features = 0;
  const double cpu_start = ProcessCpuMs();
  for (auto _ : state) {
    std::vector<cv::KeyPoint> keypoints;
    cv::Mat descriptors;
    orb->detectAndCompute(pair.left, cv::noArray(), keypoints, descriptors);
    features = keypoints.size();
  }
  state.counters["features"] = static_cast<double>(features);
  state.counters["budget"] = options.num_features;
  state.counters["process_cpu_ms"] = (ProcessCpuMs() - cpu_start) / state.iterations();
}
BENCHMARK(BM_CvOrbDetectAndCompute)->Unit(benchmark::kMillisecond);

void BM_LineSegments(benchmark::State& state) {
  const Pair& pair = TestPair();
  size_t segments = 0;
  for (auto _ : state) segments = DetectLineSegments(pair.left, LsdOptions()).size();
  state.counters["segments"] = static_cast<double>(segments);
}
BENCHMARK(BM_LineSegments)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace planeloc

BENCHMARK_MAIN();
