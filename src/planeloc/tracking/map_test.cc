// Unit tests of the tracker's containers and matching, on hand-made features (no images).
#include "planeloc/tracking/map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "planeloc/tracking/frame.h"
#include "planeloc/tracking/local_mapping.h"
#include "planeloc/tracking/matcher.h"
#include "planeloc/tracking/test_camera.h"

namespace planeloc {
namespace {

StereoCamera TestCamera() { return testing::RoundStereoCamera(); }

using testing::FeaturesOf;
using testing::RandomDescriptors;
using testing::RandomPoints;

TEST(FeatureGridTest, InAreaEqualsBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 1200), v(0, 370);
  std::uniform_int_distribution<int> level(0, 7);
  std::vector<cv::KeyPoint> keypoints;
  for (int i = 0; i < 2000; ++i)
    keypoints.emplace_back(cv::Point2f(u(rng), v(rng)), 31.f, -1.f, 0.f, level(rng));
  const FeatureGrid grid(keypoints, 1200, 370);
  for (int trial = 0; trial < 50; ++trial) {
    const double cu = u(rng), cv = v(rng), r = 5 + trial;
    std::vector<int> expected;
    for (int i = 0; i < 2000; ++i) {
      if (std::abs(keypoints[i].pt.x - cu) <= r && std::abs(keypoints[i].pt.y - cv) <= r &&
          keypoints[i].octave >= 1 && keypoints[i].octave <= 3) {
        expected.push_back(i);
      }
    }
    EXPECT_EQ(grid.InArea(keypoints, cu, cv, r, 1, 3), expected);
  }
}

TEST(SparseMapTest, CovisibilityAndErase) {
  std::mt19937 rng(5);
  const StereoCamera camera = TestCamera();
  const std::vector<Eigen::Vector3d> points = RandomPoints(30, rng);
  const cv::Mat descriptors = RandomDescriptors(30, rng);
  SparseMap map;
  const Frame frame(0, 0.0, FeaturesOf(points, descriptors, camera), camera);
  const int a = map.AddKeyframe(frame), b = map.AddKeyframe(frame), c = map.AddKeyframe(frame);
  std::vector<int> ids;
  for (int i = 0; i < 30; ++i) ids.push_back(map.AddPoint(points[i], a, i));
  for (int i = 0; i < 20; ++i) map.AddObservation(ids[i], b, i);  // a-b share 20
  for (int i = 0; i < 5; ++i) map.AddObservation(ids[i], c, i);   // a-c 5, b-c 5
  map.UpdateConnections(a);
  map.UpdateConnections(b);
  EXPECT_EQ(map.keyframe(a).covisibility.at(b), 20);
  EXPECT_EQ(map.keyframe(b).covisibility.at(a), 20);
  EXPECT_EQ(map.keyframe(c).covisibility.at(a), 5);
  EXPECT_EQ(map.BestCovisible(a, 5), (std::vector<int>{b, c}));
  EXPECT_EQ(map.BestCovisible(c, 5), (std::vector<int>{a, b}));  // tie: id ascending
  EXPECT_EQ(map.NumTrackedPoints(a, 2), 20);
  EXPECT_EQ(map.NumTrackedPoints(a, 3), 5);

  map.ErasePoint(ids[0]);
  EXPECT_FALSE(map.HasPoint(ids[0]));
  EXPECT_EQ(map.keyframe(a).map_point_ids[0], -1);
  EXPECT_EQ(map.keyframe(c).map_point_ids[0], -1);
  map.UpdateConnections(c);
  EXPECT_EQ(map.keyframe(a).covisibility.at(c), 4);

  // A point keeps a descriptor of one of its observations and a scale range around its distance.
  const MapPoint& p = map.point(ids[1]);
  EXPECT_EQ(cv::norm(p.descriptor, descriptors.row(1), cv::NORM_HAMMING), 0);
  const double distance = points[1].norm();
  EXPECT_LE(p.min_distance, distance);
  EXPECT_GE(p.max_distance, distance - 1e-9);
}

TEST(MatcherTest, FindsProjectedPointsAndRejectsInconsistentRotation) {
  std::mt19937 rng(7);
  const StereoCamera camera = TestCamera();
  const std::vector<Eigen::Vector3d> points = RandomPoints(200, rng);
  const cv::Mat descriptors = RandomDescriptors(200, rng);
  Frame frame(1, 0.1, FeaturesOf(points, descriptors, camera), camera);
  // The frame's true pose is identity; predict it 5 cm off.
  frame.cam_from_world = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.05, 0, 0));
  std::vector<MatchSource> sources;
  for (int i = 0; i < 200; ++i) {
    MatchSource s;
    s.point_in_world = points[i];
    s.descriptor = descriptors.row(i);
    s.radius = 10;
    s.angle = 45;
    sources.push_back(s);
  }
  // Ten sources see their keypoint rotated by 90 degrees: the histogram check drops them.
  for (int i = 0; i < 10; ++i) sources[i].angle = 135;
  MatchOptions options;
  options.check_orientation = true;
  const std::vector<ProjectionMatch> matches = MatchByProjection(sources, frame, camera, options);
  int in_image = 0;  // the sources that project into the image and are consistent
  for (int i = 10; i < 200; ++i) {
    const Eigen::Vector2d uv = *camera.Project(frame.cam_from_world * points[i]);
    in_image += (uv.x() >= 0 && uv.x() < camera.width && uv.y() >= 0 && uv.y() < camera.height);
  }
  ASSERT_GT(in_image, 150);
  int correct = 0;
  for (const ProjectionMatch& m : matches) {
    EXPECT_GE(m.keypoint, 10);
    correct += m.keypoint == m.source ? 1 : 0;
  }
  EXPECT_EQ(correct, in_image);
  EXPECT_EQ(static_cast<int>(matches.size()), in_image);

  // Already associated keypoints are not matched again.
  const int taken = matches.front().keypoint;
  frame.map_point_ids[taken] = 3;
  const std::vector<ProjectionMatch> again = MatchByProjection(sources, frame, camera, options);
  EXPECT_EQ(static_cast<int>(again.size()), in_image - 1);
  for (const ProjectionMatch& m : again) EXPECT_NE(m.keypoint, taken);
}

TEST(LocalMappingTest, WindowFixesAnchorsAndGauge) {
  std::mt19937 rng(11);
  const StereoCamera camera = TestCamera();
  const std::vector<Eigen::Vector3d> points = RandomPoints(60, rng);
  const cv::Mat descriptors = RandomDescriptors(60, rng);
  const Frame frame(0, 0.0, FeaturesOf(points, descriptors, camera), camera);
  SparseMap map;
  OdometryOptions options;
  options.ba_window_keyframes = 2;
  std::vector<int> kfs;
  for (int k = 0; k < 4; ++k) kfs.push_back(map.AddKeyframe(frame));
  // Keyframe 0 creates stereo points; 1..3 observe a decreasing share of them.
  const std::vector<int> created = CreateStereoPoints(map, kfs[0], camera, options);
  ASSERT_EQ(created.size(), 60u);
  for (int k = 1; k < 4; ++k) {
    for (int id : created) {
      const int keypoint = map.point(id).observations.at(kfs[0]);
      if (keypoint < 60 - 15 * k) map.AddObservation(id, kfs[k], keypoint);
    }
  }
  for (int k : kfs) map.UpdateConnections(k);
  const WindowProblem problem = BuildLocalWindow(map, kfs[3], options);
  // Window: kf 3 and its best covisible (a tie at 15 shared points: the lowest id, kf 0); all
  // others observing its points are fixed anchors; keyframe 0 (the initial pose) stays fixed.
  std::map<int, bool> fixed;
  for (const WindowKeyframe& kf : problem.keyframes) fixed[kf.id] = kf.fixed;
  ASSERT_EQ(fixed.size(), 4u);
  EXPECT_FALSE(fixed[kfs[3]]);
  EXPECT_TRUE(fixed[kfs[0]]);
  EXPECT_TRUE(fixed[kfs[1]]);
  EXPECT_TRUE(fixed[kfs[2]]);
  EXPECT_EQ(problem.points.size(), 60u);  // everything kf 0 sees
  EXPECT_EQ(problem.observations.size(), 60u + 45u + 30u + 15u);

  // A perfect BA result keeps everything; an outlier flag unlinks that observation.
  WindowBaResult result;
  result.usable = true;
  for (const WindowPoint& p : problem.points) result.point_in_world[p.id] = p.point_in_world;
  result.observation_inlier.assign(problem.observations.size(), true);
  std::size_t outlier = 0;  // an observation of a point that other keyframes also see
  while (map.point(problem.observations[outlier].point_id).observations.size() < 2) ++outlier;
  result.observation_inlier[outlier] = false;
  const BaApplyStats stats = ApplyWindowBa(map, problem, result, camera);
  EXPECT_EQ(stats.removed_observations, 1);
  EXPECT_LT(stats.median_reprojection_px, 1e-3);
  const WindowObservation& removed = problem.observations[outlier];
  EXPECT_FALSE(map.point(removed.point_id).observations.count(removed.keyframe_id));
  EXPECT_EQ(map.keyframe(removed.keyframe_id)
                .map_point_ids[map.point(removed.point_id).observations.begin()->second],
            -1);
}

// Issue 10 item 6: a BA result that comes back after a keyframe or point was moved (by a map-lock
// correction or another result) leaves the moved ones as they are, and applies to the others.
TEST(LocalMappingTest, LateResultNeverUndoesANewerChange) {
  std::mt19937 rng(12);
  const StereoCamera camera = TestCamera();
  const std::vector<Eigen::Vector3d> points = RandomPoints(40, rng);
  const Frame frame(0, 0.0, FeaturesOf(points, RandomDescriptors(40, rng), camera), camera);
  SparseMap map;
  OdometryOptions options;
  std::vector<int> kfs;
  for (int k = 0; k < 3; ++k) kfs.push_back(map.AddKeyframe(frame));
  const std::vector<int> created = CreateStereoPoints(map, kfs[0], camera, options);
  for (int k = 1; k < 3; ++k) {
    for (int id : created) map.AddObservation(id, kfs[k], map.point(id).observations.at(kfs[0]));
  }
  for (int k : kfs) map.UpdateConnections(k);
  const WindowProblem problem = BuildLocalWindow(map, kfs[2], options);
  const WindowSnapshot snapshot = SnapshotWindow(map, problem);
  ASSERT_EQ(snapshot.point_versions.size(), problem.points.size());

  // The solver's answer: every free keyframe and every point 0.2 m along x.
  const Eigen::Vector3d shift(0.2, 0, 0);
  WindowBaResult result;
  result.usable = true;
  for (const WindowKeyframe& kf : problem.keyframes) {
    if (!kf.fixed)
      result.cam_from_world[kf.id] =
          kf.cam_from_world * Rigid3d(Eigen::Quaterniond::Identity(), -shift);
  }
  for (const WindowPoint& p : problem.points)
    result.point_in_world[p.id] = p.point_in_world + shift;
  result.observation_inlier.assign(problem.observations.size(), true);
  ASSERT_EQ(result.cam_from_world.count(kfs[1]) + result.cam_from_world.count(kfs[2]), 2u);
  // Two observations flagged as outliers: one of the point that will move, one of another.
  const int moved_point = problem.points[0].id, kept_point = problem.points[1].id;
  std::size_t moved_obs = 0, kept_obs = 0;
  while (problem.observations[moved_obs].point_id != moved_point) ++moved_obs;
  while (problem.observations[kept_obs].point_id != kept_point) ++kept_obs;
  result.observation_inlier[moved_obs] = false;
  result.observation_inlier[kept_obs] = false;

  // While the BA ran: keyframe 2 and one point were moved (say by a map-lock correction).
  SparseMap late = map;
  const Rigid3d newer_pose(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, -1));
  const Eigen::Vector3d newer_point(1, 2, 30);
  late.SetKeyframePose(kfs[2], newer_pose);
  late.SetPointPosition(moved_point, newer_point);
  const BaApplyStats stats = ApplyWindowBa(late, problem, result, camera, &snapshot);
  EXPECT_EQ(stats.stale_keyframes, 1);
  EXPECT_EQ(stats.stale_points, 1);
  EXPECT_EQ(stats.keyframes, 1);
  EXPECT_EQ(stats.points, static_cast<int>(problem.points.size()) - 1);
  EXPECT_EQ(late.keyframe(kfs[2]).cam_from_world.translation, newer_pose.translation);
  EXPECT_EQ(late.point(moved_point).point_in_world, newer_point);
  EXPECT_LT((late.keyframe(kfs[1]).cam_from_world.translation -
             result.cam_from_world.at(kfs[1]).translation)
                .norm(),
            1e-12);
  EXPECT_LT((late.point(kept_point).point_in_world - result.point_in_world.at(kept_point)).norm(),
            1e-12);
  // The outlier flag of the moved point was computed against its old position: not used.
  EXPECT_TRUE(
      late.point(moved_point).observations.count(problem.observations[moved_obs].keyframe_id));
  EXPECT_FALSE(
      late.point(kept_point).observations.count(problem.observations[kept_obs].keyframe_id));

  // Without the snapshot (the old behaviour) the result overwrites the newer values.
  SparseMap overwritten = map;
  overwritten.SetPointPosition(moved_point, newer_point);
  ApplyWindowBa(overwritten, problem, result, camera);
  EXPECT_LT((overwritten.point(moved_point).point_in_world - result.point_in_world.at(moved_point))
                .norm(),
            1e-12);
  // Applied results are themselves new versions: the same late result applied twice changes
  // nothing the second time.
  const BaApplyStats again = ApplyWindowBa(late, problem, result, camera, &snapshot);
  EXPECT_EQ(again.points, 0);
  EXPECT_EQ(again.keyframes, 0);
}

TEST(LocalMappingTest, CullsPointsNotSeenAgain) {
  std::mt19937 rng(13);
  const StereoCamera camera = TestCamera();
  const std::vector<Eigen::Vector3d> points = RandomPoints(10, rng);
  const Frame frame(0, 0.0, FeaturesOf(points, RandomDescriptors(10, rng), camera), camera);
  SparseMap map;
  OdometryOptions options;
  const int k0 = map.AddKeyframe(frame);
  std::vector<int> recent = CreateStereoPoints(map, k0, camera, options);
  const int k1 = map.AddKeyframe(frame);
  map.AddObservation(recent[0], k1, 0);
  map.mutable_point(recent[1]).visible = 10;  // found 1 of 10: below 0.25
  EXPECT_EQ(CullRecentPoints(map, recent, k1, options), 1);
  const int k2 = map.AddKeyframe(frame);
  // Two keyframes later, points seen by one keyframe only go; the re-observed one stays.
  EXPECT_EQ(CullRecentPoints(map, recent, k2, options), 8);
  EXPECT_TRUE(map.HasPoint(0));
  EXPECT_EQ(map.points().size(), 1u);
}

TEST(LocalMappingTest, WindowGrowsAtTurns) {
  std::mt19937 rng(12);
  const StereoCamera camera = TestCamera();
  const std::vector<Eigen::Vector3d> points = RandomPoints(60, rng);
  const Frame frame(0, 0.0, FeaturesOf(points, RandomDescriptors(60, rng), camera), camera);
  SparseMap map;
  OdometryOptions options;
  options.ba_window_keyframes = 2;
  options.ba_window_keyframes_turn = 3;
  options.ba_turn_angle_deg = 15.0;
  std::vector<int> kfs;
  for (int k = 0; k < 4; ++k) kfs.push_back(map.AddKeyframe(frame));
  const std::vector<int> created = CreateStereoPoints(map, kfs[0], camera, options);
  for (int k = 1; k < 4; ++k) {
    for (int id : created) {
      const int keypoint = map.point(id).observations.at(kfs[0]);
      if (keypoint < 60 - 15 * k) map.AddObservation(id, kfs[k], keypoint);
    }
  }
  for (int k : kfs) map.UpdateConnections(k);
  auto free_keyframes = [](const WindowProblem& problem) {
    int free = 0;
    for (const WindowKeyframe& kf : problem.keyframes) free += !kf.fixed;
    return free;
  };
  EXPECT_FALSE(IsTurning(map, kfs[3], options));
  EXPECT_EQ(free_keyframes(BuildLocalWindow(map, kfs[3], options)), 1);  // kf 0 is fixed
  // Keyframe 3 turned by 20 degrees: one more keyframe joins the window.
  map.SetKeyframePose(kfs[3],
                      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(20.0 * std::numbers::pi / 180.0,
                                                                   Eigen::Vector3d::UnitY())),
                              Eigen::Vector3d::Zero()));
  EXPECT_TRUE(IsTurning(map, kfs[3], options));
  EXPECT_EQ(free_keyframes(BuildLocalWindow(map, kfs[3], options)), 2);
}

}  // namespace
}  // namespace planeloc
