#include "planeloc/optim/pose_optimizer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "planeloc/optim/test_scene.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

double TranslationErrorM(const Rigid3d& a, const Rigid3d& b) {
  return (a.Inverse().translation - b.Inverse().translation).norm();  // camera centres
}
double RotationErrorDeg(const Rigid3d& a, const Rigid3d& b) {
  return RotationAngle(a.rotation, b.rotation) * 180.0 / M_PI;
}

TEST(OptimizePose, RecoversPoseAndFlagsOutliers) {
  const test::PoseScene s = test::MakePoseScene(1000, 0.2, 11);
  std::mt19937 rng(5);
  const Rigid3d initial = test::Perturb(s.cam_from_world_true, 0.02, 0.2, rng);
  ASSERT_GT(TranslationErrorM(initial, s.cam_from_world_true), 0.1);

  const PoseOptimizerResult r = OptimizePose(s.camera, initial, s.observations);
  EXPECT_LT(TranslationErrorM(r.cam_from_world, s.cam_from_world_true), 0.01);
  EXPECT_LT(RotationErrorDeg(r.cam_from_world, s.cam_from_world_true), 0.05);

  ASSERT_EQ(r.inlier.size(), s.observations.size());
  int flagged_outliers = 0, true_outliers = 0, kept_inliers = 0, true_inliers = 0;
  for (size_t i = 0; i < r.inlier.size(); ++i) {
    if (s.is_outlier[i]) {
      ++true_outliers;
      flagged_outliers += r.inlier[i] ? 0 : 1;
    } else {
      ++true_inliers;
      kept_inliers += r.inlier[i] ? 1 : 0;
    }
  }
  EXPECT_EQ(flagged_outliers, true_outliers);  // 20+ px errors are far beyond chi2
  // 95 % chi-square gates keep ~95 % of the clean measurements.
  EXPECT_GT(kept_inliers, 0.9 * true_inliers);
  EXPECT_EQ(r.num_inliers, kept_inliers);
}

TEST(OptimizePose, MonocularObservationsOnly) {
  test::PoseScene s = test::MakePoseScene(300, 0.0, 12);
  for (PoseObservation& o : s.observations) o.u_right = -1;
  std::mt19937 rng(6);
  const Rigid3d initial = test::Perturb(s.cam_from_world_true, 0.01, 0.1, rng);
  const PoseOptimizerResult r = OptimizePose(s.camera, initial, s.observations);
  // Mono only: depth comes from the known points, so the pose is still well determined.
  EXPECT_LT(TranslationErrorM(r.cam_from_world, s.cam_from_world_true), 0.03);
  EXPECT_LT(RotationErrorDeg(r.cam_from_world, s.cam_from_world_true), 0.1);
  EXPECT_GT(r.num_inliers, 250);
}

TEST(OptimizePose, DeterministicBitForBit) {
  const test::PoseScene s = test::MakePoseScene(500, 0.2, 13);
  std::mt19937 rng(7);
  const Rigid3d initial = test::Perturb(s.cam_from_world_true, 0.02, 0.2, rng);
  const PoseOptimizerResult a = OptimizePose(s.camera, initial, s.observations);
  const PoseOptimizerResult b = OptimizePose(s.camera, initial, s.observations);
  EXPECT_EQ(a.cam_from_world.rotation.coeffs(), b.cam_from_world.rotation.coeffs());
  EXPECT_EQ(a.cam_from_world.translation, b.cam_from_world.translation);
  EXPECT_EQ(a.inlier, b.inlier);
}

TEST(OptimizePose, TooFewObservationsKeepsInitialPose) {
  const test::PoseScene s = test::MakePoseScene(5, 0.0, 14);
  std::mt19937 rng(8);
  const Rigid3d initial = test::Perturb(s.cam_from_world_true, 0.01, 0.1, rng);
  const PoseOptimizerResult r = OptimizePose(s.camera, initial, s.observations);
  EXPECT_EQ(r.cam_from_world.translation, initial.translation);
  EXPECT_EQ(r.inlier.size(), 5u);
}

TEST(OptimizePose, PointsBehindCameraAreOutliers) {
  test::PoseScene s = test::MakePoseScene(200, 0.0, 15);
  // Mirror one point behind the camera.
  const Rigid3d world_from_cam = s.cam_from_world_true.Inverse();
  Eigen::Vector3d p = s.cam_from_world_true * s.observations[0].point_in_world;
  p.z() = -p.z();
  s.observations[0].point_in_world = world_from_cam * p;
  const PoseOptimizerResult r = OptimizePose(s.camera, s.cam_from_world_true, s.observations);
  EXPECT_FALSE(r.inlier[0]);
  EXPECT_LT(TranslationErrorM(r.cam_from_world, s.cam_from_world_true), 0.01);
}

TEST(OptimizePose, OptionsCheck) {
  PoseOptimizerOptions o;
  EXPECT_NO_THROW(o.Check());
  o.rounds = 0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = {};
  o.chi2_stereo = 0;
  EXPECT_THROW(o.Check(), OptionsError);
}

}  // namespace
}  // namespace planeloc
