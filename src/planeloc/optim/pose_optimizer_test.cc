#include "planeloc/optim/pose_optimizer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "planeloc/optim/test_scene.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

struct PoseScene {
  StereoCamera camera = test::KittiLikeCamera();
  Rigid3d cam_from_world_true;
  std::vector<PoseObservation> observations;
  std::vector<bool> is_outlier;
};

// `num` points seen by a camera at a known pose, 1 px Gaussian noise, a fraction of gross
// outliers (20-60 px off), stereo for points closer than 40 baselines, mono beyond.
PoseScene MakePoseScene(int num, double outlier_fraction, unsigned seed) {
  PoseScene s;
  std::mt19937 rng(seed);
  s.cam_from_world_true =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY())),
              Eigen::Vector3d(0.5, -0.2, -3.0));
  const Rigid3d world_from_cam = s.cam_from_world_true.Inverse();
  std::uniform_real_distribution<double> uu(0, s.camera.width - 1), uv(0, s.camera.height - 1);
  std::uniform_real_distribution<double> depth(3.0, 60.0), unit(0.0, 1.0), sign(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  while (static_cast<int>(s.observations.size()) < num) {
    const Eigen::Vector3d point_in_cam =
        s.camera.Unproject(Eigen::Vector2d(uu(rng), uv(rng)), depth(rng));
    const Eigen::Vector3d stereo = *s.camera.ProjectStereo(point_in_cam);
    PoseObservation o;
    o.point_in_world = world_from_cam * point_in_cam;
    o.u_left = stereo.x() + noise(rng);
    o.v = stereo.y() + noise(rng);
    const bool close = point_in_cam.z() < 40 * s.camera.baseline;
    o.u_right = close ? stereo.z() + noise(rng) : -1.0;
    const bool outlier = unit(rng) < outlier_fraction;
    if (outlier) {
      o.u_left += (sign(rng) > 0 ? 1 : -1) * (20 + 40 * unit(rng));
      o.v += (sign(rng) > 0 ? 1 : -1) * (20 + 40 * unit(rng));
      if (close) o.u_right = o.u_left - (stereo.x() - stereo.z());
    }
    s.observations.push_back(o);
    s.is_outlier.push_back(outlier);
  }
  return s;
}

double TranslationErrorM(const Rigid3d& a, const Rigid3d& b) {
  return (a.Inverse().translation - b.Inverse().translation).norm();  // camera centres
}
double RotationErrorDeg(const Rigid3d& a, const Rigid3d& b) {
  return RotationAngle(a.rotation, b.rotation) * 180.0 / M_PI;
}

TEST(OptimizePose, RecoversPoseAndFlagsOutliers) {
  const PoseScene s = MakePoseScene(1000, 0.2, 11);
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
  PoseScene s = MakePoseScene(300, 0.0, 12);
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
  const PoseScene s = MakePoseScene(500, 0.2, 13);
  std::mt19937 rng(7);
  const Rigid3d initial = test::Perturb(s.cam_from_world_true, 0.02, 0.2, rng);
  const PoseOptimizerResult a = OptimizePose(s.camera, initial, s.observations);
  const PoseOptimizerResult b = OptimizePose(s.camera, initial, s.observations);
  EXPECT_EQ(a.cam_from_world.rotation.coeffs(), b.cam_from_world.rotation.coeffs());
  EXPECT_EQ(a.cam_from_world.translation, b.cam_from_world.translation);
  EXPECT_EQ(a.inlier, b.inlier);
}

TEST(OptimizePose, TooFewObservationsKeepsInitialPose) {
  const PoseScene s = MakePoseScene(5, 0.0, 14);
  std::mt19937 rng(8);
  const Rigid3d initial = test::Perturb(s.cam_from_world_true, 0.01, 0.1, rng);
  const PoseOptimizerResult r = OptimizePose(s.camera, initial, s.observations);
  EXPECT_EQ(r.cam_from_world.translation, initial.translation);
  EXPECT_EQ(r.inlier.size(), 5u);
}

TEST(OptimizePose, PointsBehindCameraAreOutliers) {
  PoseScene s = MakePoseScene(200, 0.0, 15);
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
