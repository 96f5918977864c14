#include "planeloc/optim/pose_graph.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// A drive of `n` poses 1 m apart on a gentle curve.
std::vector<Rigid3d> Drive(int n) {
  std::vector<Rigid3d> poses;
  for (int i = 0; i < n; ++i) {
    const double yaw = 0.01 * i;
    poses.emplace_back(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())),
                       Eigen::Vector3d(20 * std::sin(yaw), 20 * (1 - std::cos(yaw)), 0.1 * i));
  }
  return poses;
}

Rigid3d Perturb(const Rigid3d& pose, std::mt19937& rng, double sigma_t, double sigma_r) {
  std::normal_distribution<double> t(0, sigma_t), r(0, sigma_r);
  const Eigen::Vector3d w(r(rng), r(rng), r(rng));
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(w.norm(), w.normalized())) * pose.rotation,
                 pose.translation + Eigen::Vector3d(t(rng), t(rng), t(rng)));
}

double MeanPositionError(const std::vector<Rigid3d>& a, const std::vector<Rigid3d>& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += (a[i].translation - b[i].translation).norm();
  return sum / a.size();
}

double MeanAngleErrorDeg(const std::vector<Rigid3d>& a, const std::vector<Rigid3d>& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += a[i].rotation.angularDistance(b[i].rotation);
  return sum / a.size() * 180 / M_PI;
}

// Priors with 5 cm / 0.2 deg noise (a GNSS/INS-like pose, as for a noisy map) and relative poses
// good to 2 mm / 0.01 deg (scan registration) between neighbours 1 and 3 apart: the graph keeps
// the frame of the priors and averages their noise away. Measured (2026-12-02) seeds 1 / 2 / 3:
// mean position error 0.083 / 0.078 / 0.080 m in the priors -> 0.0078 / 0.0096 / 0.0091 m;
// angle 0.32 / 0.32 / 0.31 deg -> 0.032 / 0.040 / 0.024 deg
// (build/bin/planeloc_optim_test --gtest_filter='SolvePoseGraph*').
TEST(SolvePoseGraph, RelativePosesAverageThePriorNoise) {
  for (const unsigned seed : {1u, 2u, 3u}) {
    std::mt19937 rng(seed);
    const std::vector<Rigid3d> truth = Drive(200);
    std::vector<PosePrior> priors;
    std::vector<Rigid3d> prior_poses;
    for (const Rigid3d& pose : truth) {
      prior_poses.push_back(Perturb(pose, rng, 0.05, 0.2 * M_PI / 180));
      priors.push_back({prior_poses.back(), 0.05, 0.2 * M_PI / 180});
    }
    std::vector<RelativePose> edges;
    for (int i = 0; i < static_cast<int>(truth.size()); ++i) {
      for (const int step : {1, 3}) {
        if (i + step >= static_cast<int>(truth.size())) continue;
        const Rigid3d measured =
            Perturb(truth[i].Inverse() * truth[i + step], rng, 0.002, 0.01 * M_PI / 180);
        edges.push_back({i, i + step, measured, 0.002, 0.01 * M_PI / 180});
      }
    }
    const PoseGraphResult result = SolvePoseGraph(priors, edges, {});
    ASSERT_TRUE(result.usable);
    ASSERT_EQ(result.world_from_node.size(), truth.size());
    const double before = MeanPositionError(prior_poses, truth);
    const double after = MeanPositionError(result.world_from_node, truth);
    const double angle_before = MeanAngleErrorDeg(prior_poses, truth);
    const double angle_after = MeanAngleErrorDeg(result.world_from_node, truth);
    EXPECT_GT(before, 0.07) << "seed " << seed;
    EXPECT_LT(after, 0.018) << "seed " << seed;       // 1.9x the worst measured
    EXPECT_LT(angle_after, 0.08) << "seed " << seed;  // 2x the worst measured
    EXPECT_LT(angle_after, 0.25 * angle_before) << "seed " << seed;
  }
}

TEST(SolvePoseGraph, RejectsBadInput) {
  const std::vector<PosePrior> priors(2);
  EXPECT_THROW(SolvePoseGraph(priors, {{0, 2, Rigid3d()}}, {}), std::invalid_argument);
  EXPECT_THROW(SolvePoseGraph(priors, {{0, 0, Rigid3d()}}, {}), std::invalid_argument);
  EXPECT_THROW(SolvePoseGraph(priors, {{0, 1, Rigid3d(), 0.0, 0.01}}, {}), std::invalid_argument);
  std::vector<PosePrior> bad = priors;
  bad[1].sigma_rotation = std::nan("");
  EXPECT_THROW(SolvePoseGraph(bad, {}, {}), std::invalid_argument);
  PoseGraphOptions options;
  options.iterations = 0;
  EXPECT_THROW(SolvePoseGraph(priors, {}, options), OptionsError);
}

}  // namespace
}  // namespace planeloc
