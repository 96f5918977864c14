// Keyframe culling, point fusion and forgetting (issue 11 item 7) on hand-made maps: which
// keyframes go, which stay, and that a merged or erased id is gone everywhere (keyframes, points,
// a late BA result).
#include "planeloc/tracking/map_maintenance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/core.hpp>
#include <random>

#include "planeloc/tracking/frame.h"
#include "planeloc/tracking/local_mapping.h"
#include "planeloc/tracking/odometry_options.h"
#include "planeloc/tracking/test_camera.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

StereoCamera TestCamera() { return testing::RoundStereoCamera(); }
constexpr double kCloseDepth = 20.0;  // OdometryOptions' 40 baselines of the 0.5 m test camera

// A frame at `cam_from_world` whose keypoint i sees points_in_world[i] (stereo, exact), at
// pyramid level `octave`, with descriptor row i.
Frame FrameOf(const std::vector<Eigen::Vector3d>& points_in_world, const cv::Mat& descriptors,
              const Rigid3d& cam_from_world, int octave = 0, int id = 0) {
  const StereoCamera camera = TestCamera();
  StereoFeatures f;
  f.left.descriptors = descriptors.clone();
  for (const Eigen::Vector3d& p : points_in_world) {
    const Eigen::Vector3d in_cam = cam_from_world * p;
    const Eigen::Vector3d uvr = *camera.ProjectStereo(in_cam);
    f.left.keypoints.emplace_back(cv::Point2f(uvr.x(), uvr.y()), 31.f, 45.f, 0.f, octave);
    f.u_right.push_back(static_cast<float>(uvr.z()));
    f.depth.push_back(static_cast<float>(in_cam.z()));
    f.right_index.push_back(-1);
  }
  Frame frame(id, 0.0, std::move(f), camera);
  frame.cam_from_world = cam_from_world;
  return frame;
}

using testing::RandomDescriptors;
using testing::RandomPoints;

Rigid3d Ahead(double metres) {
  return Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, -metres));
}

// Keyframes 0..count-1, 0.2 m apart, all at level `octave`, each observing the points of
// `observed[k]` (point index == keypoint index); points created by their first observer.
struct TestMap {
  SparseMap map;
  std::vector<int> keyframes;
  std::vector<int> points;  // id per point index
};
TestMap MakeMap(const std::vector<Eigen::Vector3d>& points, const cv::Mat& descriptors,
                const std::vector<std::vector<int>>& observed, const std::vector<int>& octaves) {
  TestMap t;
  t.points.assign(points.size(), -1);
  for (std::size_t k = 0; k < observed.size(); ++k) {
    const int kf = t.map.AddKeyframe(FrameOf(points, descriptors, Ahead(0.2 * k), octaves[k]));
    t.keyframes.push_back(kf);
    for (const int i : observed[k]) {
      if (t.points[i] < 0) {
        t.points[i] = t.map.AddPoint(points[i], kf, i);
      } else {
        t.map.AddObservation(t.points[i], kf, i);
      }
    }
  }
  for (const int kf : t.keyframes) t.map.UpdateConnections(kf);
  return t;
}

std::vector<int> Range(int begin, int end) {
  std::vector<int> r;
  for (int i = begin; i < end; ++i) r.push_back(i);
  return r;
}

MapMaintenanceOptions CullOnly(int keep_newest = 1) {
  MapMaintenanceOptions options;
  options.cull_keep_newest = keep_newest;
  return options;
}

TEST(KeyframeCullingTest, RedundantKeyframeIsErasedEverywhere) {
  std::mt19937 rng(1);
  const std::vector<Eigen::Vector3d> points = RandomPoints(20, rng);
  // Five keyframes all seeing the 20 points: keyframe 1's points are seen by 0, 2, 3, 4.
  TestMap t =
      MakeMap(points, RandomDescriptors(20, rng), std::vector(5, Range(0, 20)), {0, 0, 0, 0, 0});
  const std::vector<int> erased =
      CullRedundantKeyframes(t.map, t.keyframes[4], kCloseDepth, CullOnly());
  // Keyframe 1 goes (4 other observers each). Then keyframe 2's points still have 3 other
  // observers (0, 3, 4): redundant too. Keyframe 3's then have only 2 (0, 4): it stays. 0 is the
  // first keyframe, 4 the newest.
  EXPECT_EQ(erased, (std::vector<int>{t.keyframes[1], t.keyframes[2]}));
  EXPECT_FALSE(t.map.HasKeyframe(t.keyframes[1]));
  EXPECT_FALSE(t.map.HasKeyframe(t.keyframes[2]));
  for (const int kf : {0, 3, 4}) {
    ASSERT_TRUE(t.map.HasKeyframe(t.keyframes[kf]));
    const auto& covisibility = t.map.keyframe(t.keyframes[kf]).covisibility;
    EXPECT_EQ(covisibility.count(t.keyframes[1]) + covisibility.count(t.keyframes[2]), 0u);
  }
  for (const int id : t.points) {
    ASSERT_TRUE(t.map.HasPoint(id));  // still seen by 0, 3 and 4
    const MapPoint& point = t.map.point(id);
    EXPECT_EQ(point.observations.size(), 3u);
    EXPECT_EQ(point.observations.count(t.keyframes[1]) + point.observations.count(t.keyframes[2]),
              0u);
    EXPECT_TRUE(t.map.HasKeyframe(point.reference_keyframe_id));
  }
}

TEST(KeyframeCullingTest, NinetyPercentBoundary) {
  std::mt19937 rng(2);
  const std::vector<Eigen::Vector3d> points = RandomPoints(40, rng);
  const cv::Mat descriptors = RandomDescriptors(40, rng);
  // Keyframe 1 sees points 0..19; keyframes 0, 2, 3, 4 see only the first `shared` of them (and
  // points 20..39, to keep keyframe 1 covisible with the newest).
  for (const auto& [shared, culled] : {std::pair{19, true}, std::pair{18, false}}) {
    std::vector<int> others = Range(0, shared);
    for (int i = 20; i < 40; ++i) others.push_back(i);
    TestMap t = MakeMap(points, descriptors, {others, Range(0, 20), others, others, others},
                        {0, 0, 0, 0, 0});
    // 19 of 20 = 95 % > 90 %: culled; 18 of 20 = 90 % is not more than 90 %: kept.
    const std::vector<int> erased =
        CullRedundantKeyframes(t.map, t.keyframes[4], kCloseDepth, CullOnly());
    EXPECT_EQ(!t.map.HasKeyframe(t.keyframes[1]), culled) << shared;
    EXPECT_EQ(std::count(erased.begin(), erased.end(), t.keyframes[1]), culled ? 1 : 0);
  }
}

TEST(KeyframeCullingTest, ObserversAtCoarserLevelsDoNotCount) {
  std::mt19937 rng(3);
  const std::vector<Eigen::Vector3d> points = RandomPoints(20, rng);
  // Keyframe 1 sees the points at level 0; the others at level 2 (> 0 + 1): it is the only fine
  // view of them and stays.
  TestMap t =
      MakeMap(points, RandomDescriptors(20, rng), std::vector(5, Range(0, 20)), {2, 0, 2, 2, 2});
  const std::vector<int> erased =
      CullRedundantKeyframes(t.map, t.keyframes[4], kCloseDepth, CullOnly());
  EXPECT_TRUE(t.map.HasKeyframe(t.keyframes[1]));
  EXPECT_EQ(std::count(erased.begin(), erased.end(), t.keyframes[1]), 0);
}

TEST(KeyframeCullingTest, FirstNewestAndKeptKeyframesStay) {
  std::mt19937 rng(4);
  const std::vector<Eigen::Vector3d> points = RandomPoints(20, rng);
  const cv::Mat descriptors = RandomDescriptors(20, rng);
  // Seven keyframes all seeing everything: every one but the protected is redundant.
  TestMap t = MakeMap(points, descriptors, std::vector(7, Range(0, 20)), {0, 0, 0, 0, 0, 0, 0});
  // Keep the 3 newest (4, 5, 6) and keyframe 1 explicitly (say the reference keyframe).
  const std::vector<int> erased =
      CullRedundantKeyframes(t.map, t.keyframes[6], kCloseDepth, CullOnly(3), {t.keyframes[1]});
  EXPECT_TRUE(t.map.HasKeyframe(t.keyframes[0]));  // the first: the gauge of every BA
  EXPECT_TRUE(t.map.HasKeyframe(t.keyframes[1]));
  for (const int k : {4, 5, 6}) EXPECT_TRUE(t.map.HasKeyframe(t.keyframes[k])) << k;
  EXPECT_EQ(erased, (std::vector<int>{t.keyframes[2], t.keyframes[3]}));
}

TEST(KeyframeCullingTest, FarPointsAreNotCounted) {
  std::mt19937 rng(5);
  const std::vector<Eigen::Vector3d> points = RandomPoints(20, rng);
  TestMap t =
      MakeMap(points, RandomDescriptors(20, rng), std::vector(5, Range(0, 20)), {0, 0, 0, 0, 0});
  // With a close depth below every point (5 m and more) keyframe 1 has no close point to judge by.
  const std::vector<int> erased = CullRedundantKeyframes(t.map, t.keyframes[4], 4.0, CullOnly());
  EXPECT_TRUE(erased.empty());
}

TEST(PointFusionTest, DuplicatesAreMergedAndIdsStayValid) {
  std::mt19937 rng(6);
  const StereoCamera camera = TestCamera();
  const std::vector<Eigen::Vector3d> points = RandomPoints(30, rng);
  const cv::Mat descriptors = RandomDescriptors(30, rng);
  // Keypoint 21 of keyframes 0 and 1 looks nothing like keyframe 2's (all bits flipped).
  cv::Mat flipped = descriptors.clone();
  cv::bitwise_not(descriptors.row(21), flipped.row(21));
  SparseMap map;
  const int kf0 = map.AddKeyframe(FrameOf(points, flipped, Ahead(0.0)));
  const int kf1 = map.AddKeyframe(FrameOf(points, flipped, Ahead(0.3)));
  const int kf2 = map.AddKeyframe(FrameOf(points, descriptors, Ahead(0.6)));
  // Points 0..19 are shared by all three (a covisible neighbourhood). Point 20 exists twice: `a`
  // created by keyframe 0 and also seen by keyframe 1, `b` created by keyframe 2 from the same
  // keypoint (same place, same descriptor) without knowing of `a`.
  std::vector<int> shared;
  for (int i = 0; i < 20; ++i) {
    shared.push_back(map.AddPoint(points[i], kf0, i));
    map.AddObservation(shared.back(), kf1, i);
    map.AddObservation(shared.back(), kf2, i);
  }
  const int a = map.AddPoint(points[20], kf0, 20);
  map.AddObservation(a, kf1, 20);
  const int b = map.AddPoint(points[20] + Eigen::Vector3d(0.01, 0, 0), kf2, 20);
  // Point 21 of keyframe 2 has no counterpart anywhere: it stays alone.
  const int lonely = map.AddPoint(points[21], kf2, 21);
  for (const int kf : {kf0, kf1, kf2}) map.UpdateConnections(kf);
  const std::uint64_t a_version = map.point(a).version;
  const int a_visible = map.point(a).visible, b_visible = map.point(b).visible;

  const std::vector<int> dropped = FuseWithNeighbours(map, kf2, camera, MapMaintenanceOptions{});

  // `a` has two observers, `b` one: `a` survives with all three.
  EXPECT_EQ(dropped, std::vector<int>{b});
  EXPECT_FALSE(map.HasPoint(b));
  ASSERT_TRUE(map.HasPoint(a));
  const MapPoint& survivor = map.point(a);
  EXPECT_EQ(survivor.observations, (std::map<int, int>{{kf0, 20}, {kf1, 20}, {kf2, 20}}));
  for (const int kf : {kf0, kf1, kf2}) EXPECT_EQ(map.keyframe(kf).map_point_ids[20], a);
  EXPECT_EQ(survivor.visible, a_visible + b_visible);
  EXPECT_NE(survivor.version, a_version);  // a BA solved before the merge must skip it
  ASSERT_TRUE(map.HasPoint(lonely));
  EXPECT_EQ(map.point(lonely).observations.size(), 1u);
  // No keyframe names an erased point.
  for (const auto& [id, kf] : map.keyframes()) {
    for (const int point_id : kf.map_point_ids) {
      if (point_id >= 0) {
        EXPECT_TRUE(map.HasPoint(point_id)) << id;
      }
    }
  }
  // Covisibility of the new keyframe counts the merged point: 21 shared with 0 and 1.
  EXPECT_EQ(map.keyframe(kf2).covisibility.at(kf0), 21);
  EXPECT_EQ(map.keyframe(kf2).covisibility.at(kf1), 21);
}

TEST(PointFusionTest, DifferentDescriptorIsNotMerged) {
  std::mt19937 rng(7);
  const StereoCamera camera = TestCamera();
  const std::vector<Eigen::Vector3d> points = RandomPoints(21, rng);
  cv::Mat descriptors = RandomDescriptors(21, rng);
  cv::Mat other = descriptors.clone();
  other.row(20).setTo(cv::Scalar(0));
  descriptors.row(20).setTo(cv::Scalar(255));  // 256 bits apart from `other`'s row
  SparseMap map;
  const int kf0 = map.AddKeyframe(FrameOf(points, descriptors, Ahead(0.0)));
  const int kf1 = map.AddKeyframe(FrameOf(points, other, Ahead(0.3)));
  for (int i = 0; i < 20; ++i) {
    map.AddObservation(map.AddPoint(points[i], kf0, i), kf1, i);
  }
  const int a = map.AddPoint(points[20], kf0, 20);
  const int b = map.AddPoint(points[20], kf1, 20);
  for (const int kf : {kf0, kf1}) map.UpdateConnections(kf);
  const std::vector<int> dropped = FuseWithNeighbours(map, kf1, camera, MapMaintenanceOptions{});
  EXPECT_TRUE(dropped.empty());
  EXPECT_TRUE(map.HasPoint(a));
  EXPECT_TRUE(map.HasPoint(b));
  EXPECT_EQ(map.point(a).observations.size(), 1u);
}

TEST(PointFusionTest, FreeKeypointGetsTheObservation) {
  std::mt19937 rng(8);
  const StereoCamera camera = TestCamera();
  const std::vector<Eigen::Vector3d> points = RandomPoints(21, rng);
  const cv::Mat descriptors = RandomDescriptors(21, rng);
  SparseMap map;
  const int kf0 = map.AddKeyframe(FrameOf(points, descriptors, Ahead(0.0)));
  const int kf1 = map.AddKeyframe(FrameOf(points, descriptors, Ahead(0.3)));
  for (int i = 0; i < 20; ++i) map.AddObservation(map.AddPoint(points[i], kf0, i), kf1, i);
  // Keyframe 1 saw point 20 but tracking missed it: its keypoint 20 is free.
  const int missed = map.AddPoint(points[20], kf0, 20);
  for (const int kf : {kf0, kf1}) map.UpdateConnections(kf);
  EXPECT_TRUE(FuseWithNeighbours(map, kf1, camera, MapMaintenanceOptions{}).empty());
  EXPECT_EQ(map.point(missed).observations, (std::map<int, int>{{kf0, 20}, {kf1, 20}}));
  EXPECT_EQ(map.keyframe(kf1).map_point_ids[20], missed);
}

TEST(ForgetTest, OldestGoButFirstAndKeptStay) {
  std::mt19937 rng(9);
  const std::vector<Eigen::Vector3d> points = RandomPoints(10, rng);
  // Keyframe k sees points k and k + 1 (a chain); 8 keyframes.
  std::vector<std::vector<int>> observed;
  for (int k = 0; k < 8; ++k) observed.push_back({k, k + 1});
  TestMap t = MakeMap(points, RandomDescriptors(10, rng), observed, std::vector(8, 0));
  MapMaintenanceOptions options;
  options.keep_keyframes = 4;
  const std::vector<int> erased = ForgetOldKeyframes(t.map, options, {t.keyframes[2]});
  // 8 - 1 (first) - 4 = 3 to go: the oldest besides 0, skipping the kept keyframe 2.
  EXPECT_EQ(erased, (std::vector<int>{t.keyframes[1], t.keyframes[3], t.keyframes[4]}));
  EXPECT_EQ(t.map.keyframes().size(), 5u);
  EXPECT_TRUE(t.map.HasKeyframe(t.keyframes[0]));
  // Point 1 was seen by keyframes 0 and 1: it stays; point 4 only by 3 and 4: gone.
  EXPECT_TRUE(t.map.HasPoint(t.points[1]));
  EXPECT_FALSE(t.map.HasPoint(t.points[4]));
  EXPECT_TRUE(t.map.HasPoint(t.points[3]));  // keyframe 2 still sees it
  options.keep_keyframes = 0;                // off
  EXPECT_TRUE(ForgetOldKeyframes(t.map, options).empty());
}

// A BA result solved before a culling and a fusion: it must not bring back the erased keyframe
// or the merged-away point, nor overwrite the survivor (whose observations changed), and still
// apply to everything else.
TEST(MapMaintenanceTest, LateBaResultSkipsErasedAndMergedIds) {
  std::mt19937 rng(10);
  const StereoCamera camera = TestCamera();
  const std::vector<Eigen::Vector3d> points = RandomPoints(30, rng);
  const cv::Mat descriptors = RandomDescriptors(30, rng);
  SparseMap map;
  std::vector<int> kfs;
  for (int k = 0; k < 4; ++k)
    kfs.push_back(map.AddKeyframe(FrameOf(points, descriptors, Ahead(0.3 * k))));
  std::vector<int> shared;
  for (int i = 0; i < 20; ++i) {
    shared.push_back(map.AddPoint(points[i], kfs[0], i));
    for (int k = 1; k < 4; ++k) map.AddObservation(shared.back(), kfs[k], i);
  }
  const int a = map.AddPoint(points[20], kfs[0], 20);
  map.AddObservation(a, kfs[1], 20);
  const int b = map.AddPoint(points[20], kfs[3], 20);
  for (const int kf : kfs) map.UpdateConnections(kf);
  OdometryOptions options;
  const WindowProblem problem = BuildLocalWindow(map, kfs[3], options);
  const WindowSnapshot snapshot = SnapshotWindow(map, problem);
  WindowBaResult result;
  result.usable = true;
  const Eigen::Vector3d shift(0.1, 0, 0);
  for (const WindowKeyframe& kf : problem.keyframes) {
    if (!kf.fixed) {
      result.cam_from_world[kf.id] =
          kf.cam_from_world * Rigid3d(Eigen::Quaterniond::Identity(), -shift);
    }
  }
  for (const WindowPoint& p : problem.points)
    result.point_in_world[p.id] = p.point_in_world + shift;
  result.observation_inlier.assign(problem.observations.size(), true);
  ASSERT_TRUE(result.cam_from_world.count(kfs[2]));
  ASSERT_TRUE(result.point_in_world.count(b));

  // While it ran: b merged into a, keyframe 2 erased.
  ASSERT_EQ(FuseWithNeighbours(map, kfs[3], camera, MapMaintenanceOptions{}), std::vector<int>{b});
  map.EraseKeyframe(kfs[2]);
  const Eigen::Vector3d a_now = map.point(a).point_in_world;

  const BaApplyStats stats = ApplyWindowBa(map, problem, result, camera, &snapshot);
  EXPECT_FALSE(map.HasKeyframe(kfs[2]));
  EXPECT_FALSE(map.HasPoint(b));
  EXPECT_EQ(map.point(a).point_in_world, a_now);
  EXPECT_EQ(stats.stale_points, 1);
  EXPECT_GT(stats.points, 0);
  EXPECT_LT((map.point(shared[0]).point_in_world - (points[0] + shift)).norm(), 1e-12);
}

TEST(MapMaintenanceTest, OptionsAreChecked) {
  OdometryOptions options;
  EXPECT_NO_THROW(options.Check());
  // Forgetting inside the local map's reach (60 keyframes by default) is refused; 0 is "off".
  options.maintenance.keep_keyframes = 59;
  EXPECT_THROW(options.Check(), OptionsError);
  options.maintenance.keep_keyframes = 0;
  EXPECT_NO_THROW(options.Check());
  options.maintenance.cull_redundant_ratio = 0;
  EXPECT_THROW(options.Check(), OptionsError);
  options.maintenance.cull_redundant_ratio = 0.9;
  options.maintenance.fuse_radius = -1;
  EXPECT_THROW(options.Check(), OptionsError);
}

}  // namespace
}  // namespace planeloc
