// The prior map's half of the local window on hand-made features: which points are tagged with
// a plane, staged activation, hysteresis, and that associating leaves the statistics to the
// caller.
#include "planeloc/prior/window_planes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "planeloc/tracking/frame.h"
#include "planeloc/tracking/local_mapping.h"
#include "planeloc/tracking/test_camera.h"

namespace planeloc {
namespace {

using testing::FeaturesOf;
using testing::RandomDescriptors;
using testing::RandomPoints;

StereoCamera TestCamera() { return testing::RoundStereoCamera(); }

// The window around `keyframe_id` with its points associated with `planes`.
WindowProblem Window(const SparseMap& map, int keyframe_id, const StereoCamera& camera,
                     const PlaneAssociationOptions& options, PlaneAssociator& planes) {
  WindowProblem problem = BuildLocalWindow(map, keyframe_id, OdometryOptions{});
  AssociateWindowPlanes(problem, EstimateWindowPoints(problem, map, camera, options), options,
                        planes);
  return problem;
}

TEST(WindowPlanesTest, TagsPlanePointsFromTheirStereo) {
  // Four keyframes at the origin sharing 60 random points, each later one seeing fewer of them.
  std::mt19937 rng(12);
  const StereoCamera camera = TestCamera();
  const std::vector<Eigen::Vector3d> points = RandomPoints(60, rng);
  const Frame frame(0, 0.0, FeaturesOf(points, RandomDescriptors(60, rng), camera), camera);
  SparseMap map;
  std::vector<int> kfs;
  for (int k = 0; k < 4; ++k) kfs.push_back(map.AddKeyframe(frame));
  const std::vector<int> created = CreateStereoPoints(map, kfs[0], camera, OdometryOptions{});
  for (int k = 1; k < 4; ++k) {
    for (int id : created) {
      const int keypoint = map.point(id).observations.at(kfs[0]);
      if (keypoint < 60 - 15 * k) map.AddObservation(id, kfs[k], keypoint);
    }
  }
  for (int k : kfs) map.UpdateConnections(k);
  PlaneAssociationOptions options;
  // A plane z = z0 through point 5 (the world is keyframe 0's camera frame). The expectation is
  // independent of the gate's formula: a point within 2 cm of the plane passes every gate (the
  // gate's sigma is at least Planes.mapSigma, 5 cm, so its band is at least
  // sqrt(6.635) * 5 cm = 12.9 cm), and a point beyond the 15 cm cap passes none. In between it
  // depends on the depth; no assertion there.
  const double z0 = points[5].z();
  PlaneMap plane_map;
  MapPlane wall;
  wall.id = 42;
  wall.plane_in_map = Plane(Eigen::Vector3d::UnitZ(), -z0);
  wall.area = 400;
  wall.polygon = {{-20, -20, z0}, {20, -20, z0}, {20, 20, z0}, {-20, 20, z0}};
  plane_map.planes.push_back(wall);
  options.min_associations = 1;
  ASSERT_GE(options.map_sigma, 0.05);
  ASSERT_LE(options.max_distance, 0.15);
  PlaneAssociator planes(plane_map, options);
  const WindowProblem problem = Window(map, kfs[3], camera, options, planes);
  int on_plane = 0, surely_in = 0, surely_out = 0;
  for (const WindowPoint& p : problem.points) {
    const double s = std::abs(p.point_in_world.z() - z0);
    if (s < 0.02) {
      EXPECT_TRUE(p.plane_id.has_value()) << p.point_in_world.transpose();
      ++surely_in;
    } else if (s > 0.15) {
      EXPECT_FALSE(p.plane_id.has_value()) << p.point_in_world.transpose();
      ++surely_out;
    }
    on_plane += p.plane_id.has_value();
  }
  ASSERT_GT(surely_in, 0);
  ASSERT_GT(surely_out, 0);
  ASSERT_GT(on_plane, 0);
  ASSERT_EQ(problem.planes.size(), 1u);
  EXPECT_EQ(problem.planes[0].id, 42);
  EXPECT_EQ(BuildLocalWindow(map, kfs[3], OdometryOptions{}).planes.size(), 0u);

  // Staged activation: fewer associations than min_associations, plain visual BA.
  options.min_associations = on_plane + 1;
  const WindowProblem staged = Window(map, kfs[3], camera, options, planes);
  EXPECT_TRUE(staged.planes.empty());
  for (const WindowPoint& p : staged.points) EXPECT_FALSE(p.plane_id.has_value());

  // Hysteresis: a point that a BA pulled onto the plane, while its stereo says it is 30 cm off
  // (and the gate is tighter there), stays off it: the decision uses the stereo estimate.
  options.min_associations = 1;
  int moved = -1;
  for (int id : created) {
    const Eigen::Vector3d p = map.point(id).point_in_world;
    if (std::abs(p.z() - z0) > 0.3) {  // beyond the 15 cm cap: never associated by its stereo
      moved = id;
      break;
    }
  }
  ASSERT_GE(moved, 0);
  Eigen::Vector3d pulled = map.point(moved).point_in_world;
  pulled.z() = z0;
  map.SetPointPosition(moved, pulled);
  ASSERT_EQ(planes.Associate(pulled), 42);  // by its BA position it would be on the plane
  bool seen = false;
  for (const WindowPoint& p : Window(map, kfs[3], camera, options, planes).points) {
    if (p.id != moved) continue;
    seen = true;
    EXPECT_FALSE(p.plane_id.has_value());
  }
  EXPECT_TRUE(seen);
}

// One keyframe whose 60 stereo points lie on z = 4 in front of the camera, and a plane map of
// one large wall (id 7) at z = wall_z with fitted rms `rms`.
struct WallWindow {
  WallWindow(double wall_z, double rms) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> x(-3, 3), y(-0.9, 0.9);
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 60; ++i) points.emplace_back(x(rng), y(rng), 4.0);
    const Frame frame(0, 0.0, FeaturesOf(points, RandomDescriptors(60, rng), camera), camera);
    keyframe_id = map.AddKeyframe(frame);
    CreateStereoPoints(map, keyframe_id, camera, OdometryOptions());
    map.UpdateConnections(keyframe_id);
    MapPlane wall;
    wall.id = 7;
    wall.plane_in_map = Plane(Eigen::Vector3d::UnitZ(), -wall_z);
    wall.area = 400;
    wall.rms = rms;
    wall.polygon = {{-20, -20, wall_z}, {20, -20, wall_z}, {20, 20, wall_z}, {-20, 20, wall_z}};
    plane_map.planes.push_back(wall);
  }
  StereoCamera camera = TestCamera();
  SparseMap map;
  int keyframe_id = 0;
  PlaneMap plane_map;
};

TEST(WindowPlanesTest, OnlyTheCallerRecordsTheWindowInThePlanesStatistics) {
  // The wall's 60 points sit 5 cm in front of the mapped wall (z = 4 against 4.05).
  WallWindow window(4.05, 0.01);
  PlaneAssociationOptions options;
  options.min_associations = 1;
  PlaneAssociator planes(window.plane_map, options);
  WindowProblem problem = BuildLocalWindow(window.map, window.keyframe_id, OdometryOptions{});
  const WindowPointEstimates estimates =
      EstimateWindowPoints(problem, window.map, window.camera, options);
  ASSERT_EQ(estimates.size(), 60u);

  // Associating twice gives the same window and records nothing.
  WindowProblem again = problem;
  const int associations = AssociateWindowPlanes(problem, estimates, options, planes);
  EXPECT_EQ(AssociateWindowPlanes(again, estimates, options, planes), associations);
  EXPECT_GT(associations, 50);
  ASSERT_EQ(problem.planes.size(), 1u);
  EXPECT_EQ(planes.health(7).points, 0);

  // Records that are discarded (the window was moved before use) never reach the statistics.
  RecordWindow(problem, estimates, planes);
  planes.CloseRecords();
  planes.DiscardRecords();
  planes.UpdateHealth(associations);
  EXPECT_EQ(planes.health(7).points, 0);

  // Committed records do, with each point's signed distance from the wall.
  RecordWindow(problem, estimates, planes);
  planes.FinishRecords();
  planes.UpdateHealth(associations);
  // 59 of the 60 measured (one point's sigma along the normal is beyond statsMaxPointSigma).
  EXPECT_GE(planes.health(7).points, 55);
  EXPECT_NEAR(planes.health(7).median, -0.05, 0.01);
}

}  // namespace
}  // namespace planeloc
