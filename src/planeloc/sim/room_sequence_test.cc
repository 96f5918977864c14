#include "planeloc/sim/room_sequence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "planeloc/io/asl_sequence.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/io/point_cloud.h"
#include "planeloc/io/trajectory.h"
#include "planeloc/sim/raycast.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc::sim {
namespace {

// One short room drive shared by the tests (the survey scan takes a few seconds).
class RoomSequenceTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir("planeloc-room");
    SimOptions options = SimOptions::FromPreset("room");
    options.seed = 4;
    options.frames = 4;
    options.show_progress = false;
    result_ = new SimResult(GenerateSequence(options, dir_->path()));
    scenario_ = new Scenario(BuildScenario(options));
  }
  static void TearDownTestSuite() {
    delete scenario_;
    delete result_;
    delete dir_;
  }
  static TempDir* dir_;
  static SimResult* result_;
  static Scenario* scenario_;
};
TempDir* RoomSequenceTest::dir_ = nullptr;
SimResult* RoomSequenceTest::result_ = nullptr;
Scenario* RoomSequenceTest::scenario_ = nullptr;

TEST_F(RoomSequenceTest, WritesAnAslSequenceWithItsGroundTruth) {
  const AslSequence sequence = AslSequence::Open(result_->sequence_dir);
  ASSERT_EQ(sequence.size(), 4u);
  EXPECT_EQ(sequence.unpaired_frames(), 0u);
  EXPECT_EQ(sequence.camera().width, 752);
  EXPECT_EQ(sequence.camera().height, 480);
  EXPECT_NEAR(sequence.camera().baseline, 0.1101, 5e-4);  // EuRoC's stereo baseline
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(sequence.timestamp_ns(i),
              kRoomFirstStampNs + static_cast<std::int64_t>(i) * 50000000);
  }
  // poses/00.txt is the rectified left camera, as the reader maps the body's ground truth.
  const std::vector<Rigid3d> poses = ReadKittiTrajectory(result_->poses_path).world_from_cam;
  ASSERT_EQ(poses.size(), 4u);
  const auto gt_csv = result_->sequence_dir / "state_groundtruth_estimate0" / "data.csv";
  for (std::size_t i = 0; i < 4; ++i) {
    const Rigid3d from_csv = sequence.CameraPoseFromGroundTruth(gt_csv, i);
    EXPECT_LT((from_csv.translation - poses[i].translation).norm(), 1e-6) << i;
    EXPECT_LT(from_csv.rotation.angularDistance(poses[i].rotation), 1e-6) << i;
    // The raw camera 0 the scenario flew and the rectified one share their centre.
    EXPECT_LT((poses[i].translation - scenario_->world_from_cam[i].translation).norm(), 1e-6);
  }
  EXPECT_EQ(ReadPlaneMap(result_->planes_path).planes.size(), scenario_->world.planes.size());
}

// The whole camera chain (EuRoC's intrinsics and distortion, the two T_BS, the rendering, the
// reader's rectification) agrees with the geometry: texture matched along a rectified row gives
// the depth the ray cast from the rectified camera gives.
TEST_F(RoomSequenceTest, RectifiedPairsMatchAlongRowsAtTheTrueDepth) {
  const AslSequence sequence = AslSequence::Open(result_->sequence_dir);
  const StereoPair pair = sequence.LoadStereoPair(0);
  const StereoCamera& camera = sequence.camera();
  const Rigid3d world_from_cam = result_->world_from_cam[0];
  const Scene scene(scenario_->world);
  cv::Mat left, right;
  pair.left.convertTo(left, CV_32F);
  pair.right.convertTo(right, CV_32F);
  const int half = 5;
  std::vector<double> relative_errors;
  for (int y = 40; y < camera.height - 40; y += 16) {
    for (int x = 120; x < camera.width - 40; x += 16) {
      const cv::Rect patch(x - half, y - half, 2 * half + 1, 2 * half + 1);
      cv::Scalar mean, stddev;
      cv::meanStdDev(left(patch), mean, stddev);
      if (stddev[0] < 12.0) continue;  // untextured: no reliable match
      // Normalized cross-correlation along the same row, disparities 1..100 px.
      const cv::Rect strip(std::max(half, x - 100) - half, y - half,
                           x - std::max(half, x - 100) + 2 * half + 1, 2 * half + 1);
      cv::Mat scores;
      cv::matchTemplate(right(strip), left(patch), scores, cv::TM_CCOEFF_NORMED);
      double best = 0.0;
      cv::Point at;
      cv::minMaxLoc(scores, nullptr, &best, nullptr, &at);
      if (best < 0.95 || at.x == 0 || at.x + 1 >= scores.cols) continue;
      const float l = scores.at<float>(0, at.x - 1), c = scores.at<float>(0, at.x),
                  r = scores.at<float>(0, at.x + 1);
      const double sub = at.x + 0.5 * (l - r) / (l - 2.0f * c + r);
      const double disparity = x - (strip.x + half + sub);
      if (disparity < 1.0) continue;
      const double depth = camera.fx * camera.baseline / disparity;
      // The true depth along the pixel's ray.
      const Eigen::Vector3d ray((x - camera.cx) / camera.fx, (y - camera.cy) / camera.fy, 1.0);
      const Eigen::Vector3d dir = world_from_cam.rotation * ray.normalized();
      Hit hit;
      if (!scene.Intersect(world_from_cam.translation.cast<float>(), dir.cast<float>(), 100.0f,
                           &hit)) {
        continue;
      }
      const double true_depth = hit.t / ray.norm();
      relative_errors.push_back(std::abs(depth - true_depth) / true_depth);
    }
  }
  ASSERT_GE(relative_errors.size(), 40u);
  std::nth_element(relative_errors.begin(),
                   relative_errors.begin() + static_cast<long>(relative_errors.size() / 2),
                   relative_errors.end());
  // Measured: median 0.50 % over 482 matches (seed 4, frame 0).
  EXPECT_LT(relative_errors[relative_errors.size() / 2], 0.01);
}

// The prior map is a survey scan: dense, and on the room's surfaces.
TEST_F(RoomSequenceTest, SurveyScanLiesOnTheSurfaces) {
  const PointCloud cloud = ReadPointCloud(result_->sequence_dir / "pointcloud0" / "data.ply");
  EXPECT_GT(cloud.size(), 500000u);  // measured ~2 M points at 1 cm
  for (std::size_t i = 0; i < cloud.size(); i += cloud.size() / 300) {
    EXPECT_LT(scenario_->world.DistanceToSurface(cloud.points[i]), 0.02) << i;
  }
}

}  // namespace
}  // namespace planeloc::sim
