// Benchmarks of the optimization module: motion-only BA (OptimizePose) as run on every frame, and
// the sliding-window BA (SolveWindowBa) as run on every keyframe. Scenes are the seeded synthetic
// ones of the optim tests (optim/test_scene.h).
#include <benchmark/benchmark.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>

#include <memory>
#include <random>

#include "planeloc/optim/cost_functions.h"
#include "planeloc/optim/pose_optimizer.h"
#include "planeloc/optim/test_scene.h"
#include "planeloc/optim/window_ba.h"

namespace planeloc {
namespace {

// OptimizePose with N stereo observations (all closer than 20 m), 20 % gross outliers.
void BM_OptimizePoseStereo(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const test::PoseScene scene = test::MakePoseScene(n, 0.2, 1, 20.0);
  std::mt19937 rng(2);
  const Rigid3d initial = test::Perturb(scene.cam_from_world_true, 0.01, 0.1, rng);
  for (auto _ : state) {
    const PoseOptimizerResult r = OptimizePose(scene.camera, initial, scene.observations);
    benchmark::DoNotOptimize(r.num_inliers);
  }
  state.counters["observations"] = n;
}
BENCHMARK(BM_OptimizePoseStereo)->Arg(1000)->Arg(300)->Unit(benchmark::kMillisecond);

// One residual + Jacobian evaluation: analytic pose-only functor vs autodiff of the full
// stereo functor (the alternative for pose-only optimization).
void BM_EvaluateStereoPoseOnlyAnalytic(benchmark::State& state) {
  const auto k = PinholeStereoIntrinsics::From(test::KittiLikeCamera());
  const StereoPoseOnlyError cost(k, Eigen::Vector3d(600, 200, 580), Eigen::Vector3d(1, 2, 15), 1.0);
  double q[4] = {0.01, 0.02, 0.0, 1.0}, t[3] = {0.1, 0.0, 0.2}, r[3], jq[12], jt[9];
  const double* params[2] = {q, t};
  double* jacobians[2] = {jq, jt};
  for (auto _ : state) {
    cost.Evaluate(params, r, jacobians);
    benchmark::DoNotOptimize(jq[0]);
  }
}
BENCHMARK(BM_EvaluateStereoPoseOnlyAnalytic);

void BM_EvaluateStereoAutodiff(benchmark::State& state) {
  const auto k = PinholeStereoIntrinsics::From(test::KittiLikeCamera());
  std::unique_ptr<ceres::CostFunction> cost(
      StereoReprojectionError::Create(k, Eigen::Vector3d(600, 200, 580), 1.0));
  double q[4] = {0.01, 0.02, 0.0, 1.0}, t[3] = {0.1, 0.0, 0.2}, x[3] = {1, 2, 15}, r[3];
  double jq[12], jt[9], jx[9];
  const double* params[3] = {q, t, x};
  double* jacobians[3] = {jq, jt, jx};
  for (auto _ : state) {
    cost->Evaluate(params, r, jacobians);
    benchmark::DoNotOptimize(jq[0]);
  }
}
BENCHMARK(BM_EvaluateStereoAutodiff);

// SolveWindowBa: K keyframes 1.5 m apart, P points (3/4 on the three planes), 1 px noise,
// perturbed initial poses/points, keyframe 0 fixed. Arg 2 = lambda * 100.
void BM_SolveWindowBa(benchmark::State& state) {
  test::WindowSceneConfig config;
  config.keyframes = static_cast<int>(state.range(0));
  const int points = static_cast<int>(state.range(1));
  config.points_per_plane = points / 4;
  config.off_plane_points = points - 3 * config.points_per_plane;
  const test::WindowScene scene = test::MakeWindowScene(config);
  WindowBaOptions options;
  options.lambda = state.range(2) / 100.0;
  int iterations = 0;
  for (auto _ : state) {
    const WindowBaResult r = SolveWindowBa(scene.camera, scene.problem, options);
    benchmark::DoNotOptimize(r.final_cost);
    ++iterations;
  }
  state.counters["observations"] = static_cast<double>(scene.problem.observations.size());
}
BENCHMARK(BM_SolveWindowBa)
    ->Args({10, 2000, 100})
    ->Args({10, 2000, 50})
    ->Args({5, 1000, 100})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace planeloc

BENCHMARK_MAIN();
