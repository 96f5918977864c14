// Triangulation of unmatched keypoints between two keyframes with known poses, on hand-made
// features (no images).
#include "planeloc/tracking/triangulation.h"

#include <gtest/gtest.h>

#include <random>

#include "planeloc/tracking/test_camera.h"

namespace planeloc {
namespace {

StereoCamera TestCamera() { return testing::RoundStereoCamera(); }

using testing::RandomDescriptors;

// A keyframe seeing the world points at `cam_from_world`, mono (no right match) keypoints on
// level 0, with the given descriptors.
Frame MonoFrame(int id, const Rigid3d& cam_from_world, const std::vector<Eigen::Vector3d>& points,
                const cv::Mat& descriptors, const StereoCamera& camera) {
  StereoFeatures f;
  f.left.descriptors = descriptors.clone();
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector2d uv = *camera.Project(cam_from_world * p);
    f.left.keypoints.emplace_back(cv::Point2f(uv.x(), uv.y()), 31.f, 45.f, 0.f, 0);
    f.u_right.push_back(-1.f);
    f.depth.push_back(-1.f);
  }
  Frame frame(id, 0.1 * id, std::move(f), camera);
  frame.cam_from_world = cam_from_world;
  return frame;
}

// Two keyframes 3 m apart along z (the camera moves forward) and 1 m sideways, seeing points 20
// to 60 m ahead: far beyond stereo's reach at this baseline, as the points triangulation adds.
struct Scene {
  StereoCamera camera = TestCamera();
  std::vector<Eigen::Vector3d> points;
  Rigid3d cam_a_from_world, cam_b_from_world;
  cv::Mat descriptors;
};

Scene MakeScene(int n, std::mt19937& rng) {
  Scene scene;
  std::uniform_real_distribution<double> x(-15, 15), y(-4, 4), z(20, 60);
  for (int i = 0; i < n; ++i) scene.points.emplace_back(x(rng), y(rng), z(rng));
  scene.cam_a_from_world = Rigid3d();
  scene.cam_b_from_world = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-1, 0, -3));
  scene.descriptors = RandomDescriptors(n, rng);
  return scene;
}

TEST(TriangulationTest, RecoversPointsWithinOnePercent) {
  std::mt19937 rng(7);
  const Scene s = MakeScene(80, rng);
  SparseMap map;
  const int a =
      map.AddKeyframe(MonoFrame(0, s.cam_a_from_world, s.points, s.descriptors, s.camera));
  const int b =
      map.AddKeyframe(MonoFrame(1, s.cam_b_from_world, s.points, s.descriptors, s.camera));
  // A few shared points make b a covisible neighbour of a (and give b a scene depth).
  for (int i = 0; i < 5; ++i) {
    const int id = map.AddPoint(s.points[i], a, i);
    map.AddObservation(id, b, i);
  }
  map.UpdateConnections(a);
  const std::vector<int> created = TriangulateWithNeighbours(map, a, s.camera, {});
  ASSERT_GE(created.size(), 40u);  // the rest: too little parallax near the epipole
  for (int id : created) {
    const MapPoint& p = map.point(id);
    ASSERT_EQ(p.observations.size(), 2u);
    const int keypoint = p.observations.at(a);
    EXPECT_EQ(p.observations.at(b), keypoint);  // same index = the true correspondence
    const Eigen::Vector3d& truth = s.points[keypoint];
    EXPECT_LT((p.point_in_world - truth).norm(), 0.01 * truth.norm()) << keypoint;
  }
}

TEST(TriangulationTest, RejectsMatchesOffTheEpipolarLine) {
  std::mt19937 rng(8);
  Scene s = MakeScene(40, rng);
  SparseMap map;
  const int a =
      map.AddKeyframe(MonoFrame(0, s.cam_a_from_world, s.points, s.descriptors, s.camera));
  // In b, keypoint 0 is moved 30 px vertically: same descriptor, wrong geometry.
  std::vector<Eigen::Vector3d> shifted = s.points;
  Frame frame_b = MonoFrame(1, s.cam_b_from_world, shifted, s.descriptors, s.camera);
  frame_b.features.left.keypoints[0].pt.y += 30;
  const int b = map.AddKeyframe(frame_b);
  const auto matches =
      MatchForTriangulation(map.keyframe(a), map.keyframe(b), s.camera, map.scale(), {});
  EXPECT_GE(matches.size(), 30u);
  for (const auto& [i, j] : matches) {
    EXPECT_EQ(i, j);
    EXPECT_NE(i, 0);
  }
}

TEST(TriangulationTest, RejectsPointsBehindACamera) {
  std::mt19937 rng(9);
  const Scene s = MakeScene(10, rng);
  SparseMap map;
  const int a =
      map.AddKeyframe(MonoFrame(0, s.cam_a_from_world, s.points, s.descriptors, s.camera));
  const int b =
      map.AddKeyframe(MonoFrame(1, s.cam_b_from_world, s.points, s.descriptors, s.camera));
  const Keyframe& kf_a = map.keyframe(a);
  const Keyframe& kf_b = map.keyframe(b);
  const auto good = TriangulatePair(kf_a, 0, kf_b, 0, s.camera, map.scale(), {});
  ASSERT_TRUE(good.has_value());
  EXPECT_LT((*good - s.points[0]).norm(), 0.01 * s.points[0].norm());

  // Pixels of a point behind both cameras (the pinhole formula with z < 0): the rays meet there
  // with good parallax, so only the depth test can reject the pair.
  const Eigen::Vector3d behind(2, 1, -30);
  auto pixel = [&](const Rigid3d& cam_from_world) {
    const Eigen::Vector3d p = cam_from_world * behind;
    return cv::Point2f(static_cast<float>(s.camera.fx * p.x() / p.z() + s.camera.cx),
                       static_cast<float>(s.camera.fy * p.y() / p.z() + s.camera.cy));
  };
  Frame frame_c = MonoFrame(2, s.cam_a_from_world, s.points, s.descriptors, s.camera);
  Frame frame_d = MonoFrame(3, s.cam_b_from_world, s.points, s.descriptors, s.camera);
  frame_c.features.left.keypoints[1].pt = pixel(s.cam_a_from_world);
  frame_d.features.left.keypoints[1].pt = pixel(s.cam_b_from_world);
  ASSERT_TRUE(
      s.camera.InImage(Eigen::Vector2d(frame_d.keypoint(1).pt.x, frame_d.keypoint(1).pt.y)));
  const int c = map.AddKeyframe(frame_c), d = map.AddKeyframe(frame_d);
  EXPECT_FALSE(TriangulatePair(map.keyframe(c), 1, map.keyframe(d), 1, s.camera, map.scale(), {}));
}

}  // namespace
}  // namespace planeloc
