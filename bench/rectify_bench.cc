// Cost of rectifying raw stereo pairs on load (io/stereo_rectifier.h): the one-time map
// computation and the per-frame cv::remap of both images, at EuRoC (752x480) and KITTI
// (1241x376) sizes, with a made-up radial-tangential rig. The per-pair cost is measured with one
// OpenCV thread and with OpenCV's default pool (process CPU time and wall time).
//
//   build/bin/rectify_bench
#include <benchmark/benchmark.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "planeloc/io/stereo_rectifier.h"

namespace planeloc {
namespace {

struct Rig {
  RawCamera left, right;
  cv::Mat left_from_right;
};

Rig MakeRig(cv::Size size) {
  const double f = 0.6 * size.width;
  Rig rig;
  rig.left = {(cv::Mat_<double>(3, 3) << f, 0, size.width / 2.0, 0, f, size.height / 2.0, 0, 0, 1),
              (cv::Mat_<double>(1, 5) << -0.28, 0.074, 2e-4, 2e-5, 0.0)};
  rig.right = {(cv::Mat_<double>(3, 3) << f + 1, 0, size.width / 2.0 + 9, 0, f - 1,
                size.height / 2.0 + 5, 0, 0, 1),
               (cv::Mat_<double>(1, 4) << -0.283, 0.0745, -1e-4, -3.5e-5)};
  cv::Mat rotation;
  cv::Rodrigues(cv::Vec3d(0.004, -0.012, 0.002), rotation);
  rig.left_from_right = cv::Mat::eye(4, 4, CV_64F);
  rotation.copyTo(rig.left_from_right(cv::Rect(0, 0, 3, 3)));
  rig.left_from_right.at<double>(0, 3) = 0.11;
  return rig;
}

cv::Size SizeOf(const benchmark::State& state) {
  return cv::Size(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
}

void BM_RectifierMaps(benchmark::State& state) {
  const cv::Size size = SizeOf(state);
  const Rig rig = MakeRig(size);
  for (auto _ : state) {
    const StereoRectifier rectifier =
        StereoRectifier::FromExtrinsics(rig.left, rig.right, rig.left_from_right, size);
    benchmark::DoNotOptimize(rectifier.camera().fx);
  }
}

// range(2): OpenCV threads for cv::remap (1, or 0 = OpenCV's default pool).
void BM_RectifyPair(benchmark::State& state) {
  const cv::Size size = SizeOf(state);
  const int previous_threads = cv::getNumThreads();
  cv::setNumThreads(static_cast<int>(state.range(2)));
  const Rig rig = MakeRig(size);
  const StereoRectifier rectifier =
      StereoRectifier::FromExtrinsics(rig.left, rig.right, rig.left_from_right, size);
  cv::Mat left(size, CV_8UC1), right(size, CV_8UC1);
  cv::randu(left, 0, 255);
  cv::randu(right, 0, 255);
  const StereoPair raw{left, right};
  for (auto _ : state) {
    const StereoPair rectified = rectifier.Rectify(raw);
    benchmark::DoNotOptimize(rectified.left.data);
  }
  state.SetItemsProcessed(state.iterations());  // pairs
  cv::setNumThreads(previous_threads);
}

BENCHMARK(BM_RectifierMaps)->Args({752, 480})->Args({1241, 376})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RectifyPair)
    ->Args({752, 480, 1})
    ->Args({1241, 376, 1})
    ->Args({752, 480, 0})
    ->Args({1241, 376, 0})
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace planeloc

BENCHMARK_MAIN();
