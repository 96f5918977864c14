// Unit tests of the evaluator's pieces on hand-computed and synthetic data (no shared data).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

#include "planeloc/eval/alignment.h"
#include "planeloc/eval/ape.h"
#include "planeloc/eval/kitti_drift.h"
#include "planeloc/eval/pose_path.h"
#include "planeloc/eval/rpe.h"
#include "planeloc/eval/statistics.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

Eigen::Matrix4d Pose(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation;
  m.block<3, 1>(0, 3) = translation;
  return m;
}

Eigen::Matrix3d RotY(double angle) {
  return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
}

// A KITTI-like drive in the x-z ground plane: 1 m a frame, gently curving, slight height change.
PoseMatrices CurvedDrive(int frames) {
  PoseMatrices poses;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double heading = 0.0;
  for (int i = 0; i < frames; ++i) {
    poses.push_back(Pose(RotY(heading), position));
    heading += 0.01 * std::sin(0.01 * i);
    position += RotY(heading) * Eigen::Vector3d(0.0, 0.002 * std::cos(0.03 * i), 1.0);
  }
  return poses;
}

TEST(StatisticsTest, HandComputedVector) {
  const ErrorStatistics s = ComputeStatistics({1.0, 2.0, 3.0, 4.0});
  EXPECT_EQ(s.n, 4u);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);  // numpy: mean of the two middle values
  EXPECT_DOUBLE_EQ(s.sse, 30.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));  // population std, ddof 0
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(ComputeStatistics({5.0, 1.0, 3.0}).median, 3.0);
  EXPECT_THROW(ComputeStatistics({}), std::invalid_argument);
}

TEST(AlignmentTest, UmeyamaRecoversKnownSim3) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 5.0);
  Eigen::Matrix3Xd x(3, 50);
  for (int i = 0; i < x.cols(); ++i)
    x.col(i) = Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d translation(4.0, -2.0, 10.0);
  const double scale = 1.7;
  const Eigen::Matrix3Xd y = (scale * rotation * x).colwise() + translation;

  const Sim3Alignment sim3 = UmeyamaAlignment(x, y, true);
  EXPECT_EQ(sim3.type, AlignmentType::kSim3);
  EXPECT_NEAR(sim3.scale, scale, 1e-12);
  EXPECT_TRUE(sim3.rotation.isApprox(rotation, 1e-12));
  EXPECT_TRUE(sim3.translation.isApprox(translation, 1e-12));

  const Eigen::Matrix3Xd y_rigid = (rotation * x).colwise() + translation;
  const Sim3Alignment se3 = UmeyamaAlignment(x, y_rigid, false);
  EXPECT_DOUBLE_EQ(se3.scale, 1.0);
  EXPECT_TRUE(se3.rotation.isApprox(rotation, 1e-12));
  EXPECT_NEAR(se3.rotation.determinant(), 1.0, 1e-12);
}

TEST(AlignmentTest, DegeneratePointsAreAnInputError) {
  Eigen::Matrix3Xd line(3, 5);
  for (int i = 0; i < 5; ++i) line.col(i) = Eigen::Vector3d(i, 0, 0);
  EXPECT_THROW(UmeyamaAlignment(line, line, false), InputError);
  EXPECT_THROW(ParseAlignmentType("se(3)"), InputError);
}

TEST(ApeTest, Sim3AlignmentRemovesScaleAndPose) {
  const PoseMatrices reference = CurvedDrive(200);
  PoseMatrices estimate = reference;
  const Sim3Alignment distortion{
      AlignmentType::kSim3, Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
      Eigen::Vector3d(1, 2, 3), 0.5};
  ApplyAlignment(distortion, &estimate);

  ApeOptions options;
  EXPECT_GT(ComputeApe(reference, estimate, options).stats.rmse, 1.0);
  options.alignment = AlignmentType::kSim3;
  const ApeResult aligned = ComputeApe(reference, estimate, options);
  EXPECT_LT(aligned.stats.max, 1e-9);
  EXPECT_NEAR(aligned.alignment.scale, 2.0, 1e-9);
  EXPECT_EQ(aligned.stats.n, 200u);
}

TEST(ApeTest, ProjectionDropsTheNormalCoordinate) {
  PoseMatrices reference = {Pose(Eigen::Matrix3d::Identity(), {0, 0, 0}),
                            Pose(Eigen::Matrix3d::Identity(), {0, 0, 1})};
  PoseMatrices estimate = {Pose(Eigen::Matrix3d::Identity(), {3, 4, 0}),
                           Pose(Eigen::Matrix3d::Identity(), {0, 2, 1})};
  ApeOptions options;
  EXPECT_DOUBLE_EQ(ComputeApe(reference, estimate, options).stats.max, 5.0);
  options.plane = ProjectionPlane::kXz;  // y (KITTI's down axis) is dropped
  const ApeResult xz = ComputeApe(reference, estimate, options);
  EXPECT_DOUBLE_EQ(xz.errors[0], 3.0);
  EXPECT_DOUBLE_EQ(xz.errors[1], 0.0);
}

TEST(ProjectionTest, KeepsOnlyTheRotationAboutTheNormal) {
  const Eigen::Matrix3d tilted =
      RotY(0.4) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  PoseMatrices poses = {Pose(tilted, {1, 2, 3})};
  ProjectToPlane(ProjectionPlane::kXz, &poses);
  EXPECT_DOUBLE_EQ(poses[0](1, 3), 0.0);
  const Eigen::AngleAxisd remaining(Eigen::Matrix3d(poses[0].topLeftCorner<3, 3>()));
  EXPECT_NEAR(std::abs(remaining.axis().dot(Eigen::Vector3d::UnitY())), 1.0, 1e-12);
}

TEST(RpeTest, PairsFollowEvoRules) {
  // Straight line, 1 m a frame except a 3 m jump between frames 4 and 5.
  PoseMatrices poses;
  double z = 0.0;
  for (int i = 0; i < 10; ++i) {
    poses.push_back(Pose(Eigen::Matrix3d::Identity(), {0, 0, z}));
    z += i == 4 ? 3.0 : 1.0;
  }
  RpeOptions frames;
  frames.delta = 3;
  EXPECT_EQ(RpePairs(poses, frames), (IndexPairs{{0, 3}, {3, 6}, {6, 9}}));
  frames.all_pairs = true;
  EXPECT_EQ(RpePairs(poses, frames).size(), 7u);

  RpeOptions metres;
  metres.delta = 2.0;
  metres.delta_unit = DeltaUnit::kMeters;
  // Checkpoints where the path since the last checkpoint reaches >= 2 m: 2, 4, 5, 7, 9.
  EXPECT_EQ(RpePairs(poses, metres), (IndexPairs{{2, 4}, {4, 5}, {5, 7}, {7, 9}}));
  metres.all_pairs = true;  // j with path(i..j) closest to 2 m, within 10 %
  EXPECT_EQ(RpePairs(poses, metres), (IndexPairs{{0, 2}, {1, 3}, {2, 4}, {5, 7}, {6, 8}, {7, 9}}));
}

TEST(RpeTest, ConstantRelativeErrorPerPair) {
  const PoseMatrices reference = CurvedDrive(50);
  PoseMatrices estimate;
  // Each step of the estimate overshoots by 10 cm along the camera's z axis.
  estimate.push_back(reference[0]);
  for (std::size_t i = 1; i < reference.size(); ++i) {
    Eigen::Matrix4d step = RelativePose(reference[i - 1], reference[i]);
    step.block<3, 1>(0, 3) += 0.1 * step.block<3, 1>(0, 3).normalized();
    estimate.push_back(estimate.back() * step);
  }
  RpeOptions options;
  const RpeResult result = ComputeRpe(reference, estimate, options);
  EXPECT_EQ(result.translation.n, 49u);
  EXPECT_NEAR(result.translation.min, 0.1, 1e-9);
  EXPECT_NEAR(result.translation.max, 0.1, 1e-9);
  EXPECT_LT(result.rotation_deg.max, 1e-6);
}

TEST(RpeTest, OptionsAreChecked) {
  RpeOptions options;
  options.delta = 0;
  EXPECT_THROW(options.Check(), OptionsError);
  options.delta = 2.5;
  EXPECT_THROW(options.Check(), OptionsError);
  options.delta_unit = DeltaUnit::kMeters;
  EXPECT_NO_THROW(options.Check());
}

TEST(KittiDriftTest, ScaleErrorOfOnePercent) {
  // Straight drive (path length = chord, so the error is exactly 1 % of the travelled distance).
  PoseMatrices reference;
  for (int i = 0; i < 1200; ++i) {
    reference.push_back(Pose(Eigen::Matrix3d::Identity(), {0.0, 0.0, 1.0 * i}));
  }
  PoseMatrices estimate = reference;
  for (Eigen::Matrix4d& pose : estimate) pose.block<3, 1>(0, 3) *= 1.01;
  const KittiDriftResult drift = ComputeKittiDrift(reference, estimate);
  // t_err divides by the nominal length; the segment ends at the first frame *beyond* it (<= 1 m).
  EXPECT_NEAR(drift.translation_percent, 1.0, 0.011);
  EXPECT_GE(drift.translation_percent, 1.0);
  EXPECT_NEAR(drift.rotation_deg_per_100m, 0.0, 1e-6);
  // 120 start frames, segments of 100..800 m that fit in ~1199 m of path.
  EXPECT_GT(drift.segments.size(), 500u);
  for (const KittiDriftSegment& segment : drift.segments) {
    EXPECT_EQ(segment.first % 10, 0u);
    EXPECT_GT(segment.last, segment.first);
  }
}

TEST(KittiDriftTest, RotationDriftInDegreesPer100m) {
  // Straight GT; the estimate turns 0.5 deg every 100 m (about y) while keeping the positions.
  PoseMatrices reference;
  PoseMatrices estimate;
  for (int i = 0; i < 1000; ++i) {
    reference.push_back(Pose(Eigen::Matrix3d::Identity(), {0, 0, double(i)}));
    estimate.push_back(Pose(RotY(0.005 * std::numbers::pi / 180.0 * i), {0, 0, double(i)}));
  }
  const KittiDriftResult drift = ComputeKittiDrift(reference, estimate);
  EXPECT_NEAR(drift.rotation_deg_per_100m, 0.5, 0.01);
  // The rotated relative motion also misplaces the segment's end: translation error too.
  EXPECT_GT(drift.translation_percent, 0.0);
}

TEST(KittiDriftTest, ShortTrajectoryIsAnInputError) {
  const PoseMatrices poses = CurvedDrive(50);
  EXPECT_THROW(ComputeKittiDrift(poses, poses), InputError);
}

}  // namespace
}  // namespace planeloc
