#include "planeloc/prior/plane_evidence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <random>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A facade x = 6 (KITTI camera world, y down) over y in [-6, 1.65], z in [0, 40], its major
// axis along the street (z); the cameras drive along x = 0.
PlaneMap Facade() {
  PlaneMap map;
  MapPlane plane;
  plane.id = 3;
  plane.plane_in_map = Plane(Eigen::Vector3d(1, 0, 0), -6.0);
  plane.polygon = {{6, -6, 0}, {6, 1.65, 0}, {6, 1.65, 40}, {6, -6, 40}};
  plane.area = 306;
  plane.centroid = Eigen::Vector3d(6, -2.2, 20);
  plane.sigma.offset = 0.05;
  plane.sigma.normal = Eigen::Vector2d(0.0035, 0.0035);
  plane.sigma.major_axis = Eigen::Vector3d(0, 0, 1);
  map.planes.push_back(plane);
  return map;
}

// `count` points x = wall(y, z) + noise (2 cm along x), seen from cameras at (0, 0, z - 10).
std::vector<EvidencePoint> WallPoints(const std::function<double(double, double)>& wall_x,
                                      int count, int seed, int first_id = 0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> y(-5.0, 1.0), z(2.0, 38.0);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<EvidencePoint> points;
  for (int i = 0; i < count; ++i) {
    EvidencePoint point;
    point.point_id = first_id + i;
    const double py = y(rng), pz = z(rng);
    point.estimate.point_in_map = Eigen::Vector3d(wall_x(py, pz) + noise(rng), py, pz);
    point.estimate.covariance = Eigen::Matrix3d::Identity() * 0.02 * 0.02;
    point.camera_center = Eigen::Vector3d(0, 0, pz - 10);
    points.push_back(point);
  }
  return points;
}

PlaneUpdate Observe(const std::vector<EvidencePoint>& points) {
  const PlaneMap map = Facade();
  const PlaneAssociator associator(map, PlaneAssociationOptions());
  PlaneEvidence evidence(map, associator, PlaneEvidenceOptions());
  evidence.ObserveWindow(12, points);
  const std::vector<PlaneUpdate> updates = evidence.Summarize();
  EXPECT_EQ(updates.size(), 1u);
  return updates.front();
}

TEST(PlaneEvidenceTest, AWallWhereTheMapHasItIsConfirmed) {
  const PlaneUpdate update = Observe(WallPoints([](double, double) { return 6.0; }, 200, 1));
  EXPECT_EQ(update.status, PlaneUpdateStatus::kConfirmed);
  EXPECT_EQ(update.points, 200);
  EXPECT_EQ(update.frames, std::vector<int>{12});
  EXPECT_LT(std::abs(update.offset), 0.01);
  // The trajectory's 3 cm floor dominates 200 points' 2 cm noise.
  EXPECT_NEAR(update.offset_sigma, 0.03, 0.003);
}

TEST(PlaneEvidenceTest, AWallMovedBackIsCorrectedByItsOffset) {
  const PlaneUpdate update = Observe(WallPoints([](double, double) { return 6.2; }, 200, 2));
  EXPECT_EQ(update.status, PlaneUpdateStatus::kCorrected);
  EXPECT_NEAR(update.offset, 0.2, 0.01);
  // The corrected plane is the true one: x = 6.2.
  EXPECT_NEAR(update.normal.x(), 1.0, 1e-4);
  EXPECT_NEAR(update.d, -6.2, 0.01);
}

TEST(PlaneEvidenceTest, ARotatedWallGivesTheRotatedNormal) {
  // Turned by 2 deg about the vertical through the centroid: x = 6 + tan(2 deg) (z - 20).
  const double slope = std::tan(2.0 * kDeg);
  const PlaneUpdate update =
      Observe(WallPoints([slope](double, double z) { return 6.0 + slope * (z - 20.0); }, 300, 3));
  EXPECT_EQ(update.status, PlaneUpdateStatus::kCorrected);
  const Eigen::Vector3d truth = Eigen::Vector3d(1, 0, -slope).normalized();
  EXPECT_LT(std::acos(std::min(1.0, update.normal.dot(truth))), 0.1 * kDeg);
  // Points of the true wall lie on the corrected plane.
  for (const double z : {5.0, 20.0, 35.0}) {
    const Eigen::Vector3d on_wall(6.0 + slope * (z - 20.0), -1.0, z);
    EXPECT_NEAR(Plane(update.normal, update.d).SignedDistance(on_wall), 0.0, 0.01) << z;
  }
  EXPECT_NEAR(update.tilt.norm(), 2.0 * kDeg, 0.1 * kDeg);
}

TEST(PlaneEvidenceTest, PointsSeenThroughAWallContradictIt) {
  // The building is gone: the cameras see 6 m further, through where the facade was.
  std::vector<EvidencePoint> points = WallPoints([](double, double) { return 12.0; }, 100, 4);
  for (EvidencePoint& point : points) point.camera_center.z() = point.estimate.point_in_map.z();
  const PlaneUpdate update = Observe(points);
  EXPECT_EQ(update.status, PlaneUpdateStatus::kContradicted);
  EXPECT_EQ(update.through, 100);
  EXPECT_EQ(update.points, 0);
}

TEST(PlaneEvidenceTest, PointsBehindAWallButBesideItAreNoEvidence) {
  // Seen past the facade's end (z > 40): the rays cross its plane outside the outline.
  std::vector<EvidencePoint> points = WallPoints([](double, double) { return 12.0; }, 100, 5);
  for (EvidencePoint& point : points) {
    point.estimate.point_in_map.z() += 60;
    point.camera_center.z() += 60;
  }
  const PlaneUpdate update = Observe(points);
  EXPECT_EQ(update.status, PlaneUpdateStatus::kUnseen);
  EXPECT_EQ(update.through, 0);
  EXPECT_TRUE(update.frames.empty());
}

// Points at a facade's foot, 0.3 m above the road and seen nearly edge-on (0.2 m sigma along the
// facade's normal): too imprecise to measure the facade, but no measure of the road either. When
// the facade's imprecision let them pass to the road, 150 feet outvoted 100 road points and the
// road was "corrected" 0.3 m up.
TEST(PlaneEvidenceTest, AFacadeFootIsNoEvidenceOfTheRoad) {
  PlaneMap map = Facade();
  MapPlane road = map.planes.front();
  road.id = 4;
  road.plane_in_map = Plane(Eigen::Vector3d(0, -1, 0), 1.65);  // y = 1.65, y down
  road.polygon = {{-5, 1.65, 0}, {6, 1.65, 0}, {6, 1.65, 40}, {-5, 1.65, 40}};
  road.area = 440;
  road.centroid = Eigen::Vector3d(0.5, 1.65, 20);
  map.planes.push_back(road);
  std::mt19937 rng(7);
  // Feet on the street side of the facade, inside the road's outline.
  std::uniform_real_distribution<double> along(2.0, 38.0), across(-4.0, 5.0), depth(-0.3, 0.0);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<EvidencePoint> points;
  for (int i = 0; i < 250; ++i) {
    EvidencePoint point;
    point.point_id = i;
    const double z = along(rng);
    if (i < 150) {
      point.estimate.point_in_map = Eigen::Vector3d(6 + depth(rng), 1.35 + noise(rng), z);
      point.estimate.covariance = Eigen::Vector3d(0.2 * 0.2, 0.02 * 0.02, 0.02 * 0.02).asDiagonal();
    } else {
      point.estimate.point_in_map = Eigen::Vector3d(across(rng), 1.65 + noise(rng), z);
      point.estimate.covariance = Eigen::Matrix3d::Identity() * 0.02 * 0.02;
    }
    point.camera_center = Eigen::Vector3d(0, 0, z - 10);
    points.push_back(point);
  }
  const PlaneAssociator associator(map, PlaneAssociationOptions());
  PlaneEvidence evidence(map, associator, PlaneEvidenceOptions());
  evidence.ObserveWindow(5, points);
  const std::vector<PlaneUpdate> updates = evidence.Summarize();
  ASSERT_EQ(updates.size(), 2u);
  const PlaneUpdate& facade = updates[0].id == 3 ? updates[0] : updates[1];
  const PlaneUpdate& measured_road = updates[0].id == 4 ? updates[0] : updates[1];
  EXPECT_EQ(measured_road.status, PlaneUpdateStatus::kConfirmed);
  // Its own points (a few beyond the median / MAD test), none of the feet.
  EXPECT_GE(measured_road.points, 90);
  EXPECT_LE(measured_road.points, 100);
  EXPECT_LT(std::abs(measured_road.offset), 0.01);
  EXPECT_EQ(facade.points, 0);
}

TEST(PlaneEvidenceTest, FewPointsLeaveAPlaneUnseenAndResetForgetsThem) {
  EXPECT_EQ(Observe(WallPoints([](double, double) { return 6.2; }, 10, 6)).status,
            PlaneUpdateStatus::kUnseen);
  const PlaneMap map = Facade();
  const PlaneAssociator associator(map, PlaneAssociationOptions());
  PlaneEvidence evidence(map, associator, PlaneEvidenceOptions());
  evidence.ObserveWindow(4, WallPoints([](double, double) { return 6.2; }, 100, 7));
  evidence.Reset();
  evidence.ObserveWindow(9, WallPoints([](double, double) { return 6.0; }, 100, 8, 1000));
  const PlaneUpdate update = evidence.Summarize().front();
  // Only the points after the reset count; both windows' frames stay.
  EXPECT_EQ(update.status, PlaneUpdateStatus::kConfirmed);
  EXPECT_EQ(update.points, 100);
  EXPECT_EQ(update.frames, (std::vector<int>{4, 9}));
}

TEST(PlaneEvidenceTest, TheLatestEstimateOfAPointCounts) {
  const PlaneMap map = Facade();
  const PlaneAssociator associator(map, PlaneAssociationOptions());
  PlaneEvidence evidence(map, associator, PlaneEvidenceOptions());
  // The same 100 points, first 0.3 m off, then re-estimated on the wall.
  evidence.ObserveWindow(1, WallPoints([](double, double) { return 6.3; }, 100, 9));
  evidence.ObserveWindow(2, WallPoints([](double, double) { return 6.0; }, 100, 9));
  const PlaneUpdate update = evidence.Summarize().front();
  EXPECT_EQ(update.points, 100);
  EXPECT_LT(std::abs(update.offset), 0.01);
}

TEST(PlaneEvidenceTest, OptionsOutOfRangeNameTheKey) {
  PlaneEvidenceOptions options;
  options.min_points = 1;
  try {
    options.Check();
    FAIL() << "no error";
  } catch (const OptionsError& error) {
    EXPECT_NE(std::string(error.what()).find("MapUpdate.minPoints"), std::string::npos);
  }
}

}  // namespace
}  // namespace planeloc
