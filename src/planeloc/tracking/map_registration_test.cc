#include "planeloc/tracking/map_registration.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
const Eigen::Vector3d kUp(0, -1, 0);  // KITTI camera world: y down

MapPlane MakePlane(int id, const Plane& plane, std::vector<Eigen::Vector3d> polygon,
                   const std::string& kind) {
  MapPlane p;
  p.id = id;
  p.plane_in_map = plane;
  p.polygon = std::move(polygon);
  p.area = 100;
  p.kind = kind;
  p.rms = 0.01;
  return p;
}

// A straight street along +z: the road (y = 1.65), facades at x = -7 and x = +7, and optionally
// a wall across the road at z = 70 (what a car sees before a T junction).
PlaneMap Street(bool cross_wall) {
  PlaneMap map;
  map.planes.push_back(MakePlane(0, Plane(Eigen::Vector3d(0, -1, 0), 1.65),
                                 {{-7, 1.65, -10}, {7, 1.65, -10}, {7, 1.65, 70}, {-7, 1.65, 70}},
                                 "ground"));
  map.planes.push_back(MakePlane(1, Plane(Eigen::Vector3d(1, 0, 0), 7.0),
                                 {{-7, -8, -10}, {-7, 1.65, -10}, {-7, 1.65, 70}, {-7, -8, 70}},
                                 "facade"));
  map.planes.push_back(MakePlane(2, Plane(Eigen::Vector3d(-1, 0, 0), 7.0),
                                 {{7, -8, -10}, {7, 1.65, -10}, {7, 1.65, 70}, {7, -8, 70}},
                                 "facade"));
  if (cross_wall) {
    map.planes.push_back(MakePlane(3, Plane(Eigen::Vector3d(0, 0, -1), 70.0),
                                   {{-7, -8, 70}, {7, -8, 70}, {7, 1.65, 70}, {-7, 1.65, 70}},
                                   "facade"));
  }
  return map;
}

// Points as stereo would reconstruct them from a drive along z in [0, z_end]: on the road, on
// both facades (up to 25 m ahead), on the cross wall if asked, plus clutter; each with noise of
// 3 cm. Returned in the map frame.
std::vector<Eigen::Vector3d> StreetStructure(double z_end, int wall_points, std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.03);
  std::vector<Eigen::Vector3d> points;
  auto jitter = [&](Eigen::Vector3d p) {
    return Eigen::Vector3d(p + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
  };
  const double z_max = z_end + 25.0;
  for (int i = 0; i < 300; ++i) {
    points.push_back(jitter({-6.5 + 13 * unit(rng), 1.65, z_max * unit(rng)}));
  }
  for (int i = 0; i < 300; ++i) {
    const double x = i % 2 ? 7.0 : -7.0;
    points.push_back(jitter({x, 1.4 - 8 * unit(rng), z_max * unit(rng)}));
  }
  for (int i = 0; i < wall_points; ++i) {
    points.push_back(jitter({-6.5 + 13 * unit(rng), 1.4 - 8 * unit(rng), 70.0}));
  }
  for (int i = 0; i < 150; ++i) {  // trees, cars: on no plane
    points.push_back({-5 + 10 * unit(rng), -3 + 4.5 * unit(rng), z_max * unit(rng)});
  }
  return points;
}

// The start pose's error: the world (VO) frame is the map frame moved by the inverse of this.
Rigid3d TrueMapFromWorld(double yaw_deg, const Eigen::Vector3d& shift) {
  return Rigid3d(Eigen::Matrix3d(Eigen::AngleAxisd(yaw_deg * kDegree, kUp)), shift);
}

std::vector<RegistrationPoint> InWorld(const std::vector<Eigen::Vector3d>& map_points,
                                       const Rigid3d& map_from_world) {
  const Rigid3d world_from_map = map_from_world.Inverse();
  std::vector<RegistrationPoint> points;
  for (const Eigen::Vector3d& p : map_points) points.push_back({world_from_map * p, 0.05});
  return points;
}

// Camera 40 m down the street, looking along it; its pose in the (wrong) world frame.
Rigid3d CameraInWorld(const Rigid3d& map_from_world) {
  return map_from_world.Inverse() * Rigid3d(Eigen::Quaterniond::Identity(), {0, 0, 40});
}

RegistrationPrior DefaultPrior() {
  // The start camera at the origin of the world frame: sigmas 2 m, 0.5 m, 5 deg.
  return RegistrationPrior::FromSigmas(Eigen::Vector3d::Zero(), kUp, 2.0, 0.5, 5 * kDegree,
                                       1 * kDegree);
}

TEST(MapRegistrationTest, CornerWallLocksAllSixDof) {
  std::mt19937 rng(1);
  const Rigid3d truth = TrueMapFromWorld(4.0, {1.2, 0.3, -0.8});
  const MapRegistration registration(Street(true), MapRegistrationOptions());
  const RegistrationResult result = registration.Register(
      InWorld(StreetStructure(40, 200, rng), truth), DefaultPrior(), CameraInWorld(truth));
  ASSERT_EQ(result.lock, MapLock::kLocked) << result.reason;
  // The correction maps a world point where the truth does (checked at the camera and 30 m off).
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(0, 0, 40), Eigen::Vector3d(5, -3, 10)}) {
    EXPECT_LT((result.map_from_world * x - truth * x).norm(), 0.03) << x.transpose();
  }
  EXPECT_LT(RotationAngle(result.map_from_world.rotation, truth.rotation), 0.1 * kDegree);
  for (int dof = 0; dof < kNumDofs; ++dof) EXPECT_TRUE(result.constrained[dof]) << dof;
  EXPECT_GT(result.inlier_ratio, 0.8);  // 800 of 950 points lie on planes
  EXPECT_LT(result.inlier_ratio, 0.9);  // the clutter is not counted
  EXPECT_LT(result.rms, 0.05);
}

TEST(MapRegistrationTest, StraightStreetIsAPartialLockWithAlongTrackFree) {
  std::mt19937 rng(2);
  const Rigid3d truth = TrueMapFromWorld(-3.0, {-1.5, -0.2, 1.1});
  const MapRegistration registration(Street(false), MapRegistrationOptions());
  const Rigid3d camera = CameraInWorld(truth);
  const RegistrationResult result =
      registration.Register(InWorld(StreetStructure(40, 0, rng), truth), DefaultPrior(), camera);
  ASSERT_EQ(result.lock, MapLock::kPartial) << result.reason;
  EXPECT_FALSE(result.constrained[kAlongTrack]);
  EXPECT_GT(result.dof_sigma[kAlongTrack], 1.0);
  for (int dof = kLateral; dof < kNumDofs; ++dof) EXPECT_TRUE(result.constrained[dof]) << dof;
  // At the camera: lateral (x) and vertical (y) corrected, heading corrected; along-track (z)
  // keeps the error the start pose gave it (the prior's mean: no correction along z).
  const Eigen::Vector3d corrected = result.map_from_world * camera.translation;
  const Eigen::Vector3d truth_position(0, 0, 40);
  EXPECT_NEAR(corrected.x(), truth_position.x(), 0.05);
  EXPECT_NEAR(corrected.y(), truth_position.y(), 0.05);
  const Eigen::Vector3d uncorrected_along = truth.Inverse() * truth_position;  // world frame
  // Along z the correction is only the heading's rotation about the start: under 0.3 m.
  EXPECT_NEAR(corrected.z(), uncorrected_along.z(), 0.3);
  EXPECT_GT(std::abs(corrected.z() - truth_position.z()), 0.7);  // the 1.1 m error stays
  EXPECT_LT(RotationAngle(result.map_from_world.rotation, truth.rotation), 0.15 * kDegree);
}

TEST(MapRegistrationTest, RoadAloneNeverLocks) {
  PlaneMap road;
  road.planes.push_back(Street(false).planes.front());
  std::mt19937 rng(3);
  const Rigid3d truth = TrueMapFromWorld(2.0, {0.5, 0.1, 0.5});
  const MapRegistration registration(road, MapRegistrationOptions());
  const RegistrationResult result = registration.Register(
      InWorld(StreetStructure(40, 0, rng), truth), DefaultPrior(), CameraInWorld(truth));
  EXPECT_EQ(result.lock, MapLock::kSearching);
  EXPECT_TRUE(result.constrained[kVertical]);  // the road fixes height ...
  EXPECT_FALSE(result.constrained[kLateral]);  // ... but nothing else
  EXPECT_FALSE(result.constrained[kYaw]);
  EXPECT_NE(result.reason.find("lateral"), std::string::npos) << result.reason;
}

TEST(MapRegistrationTest, TwoIdenticalCrossWallsWithinTheWidePriorAreAmbiguous) {
  // A second wall across the road 8 m before the first, identical in extent: with a prior of
  // 8 m along-track the structure fits either, and registration must not pick one.
  PlaneMap map = Street(true);
  MapPlane second = map.planes.back();
  second.id = 4;
  second.plane_in_map = Plane(Eigen::Vector3d(0, 0, -1), 62.0);
  for (Eigen::Vector3d& p : second.polygon) p.z() = 62.0;
  map.planes.push_back(second);
  std::vector<Eigen::Vector3d> structure;
  std::mt19937 rng(4);
  for (const Eigen::Vector3d& p : StreetStructure(40, 200, rng)) {
    if (p.z() < 62.0 - 0.5 || p.z() > 69.0) structure.push_back(p);  // the near wall is hidden
  }
  const Rigid3d truth = TrueMapFromWorld(1.0, {0.4, 0.1, 0.6});
  const RegistrationPrior wide = RegistrationPrior::FromSigmas(Eigen::Vector3d::Zero(), kUp, 8.0,
                                                               0.5, 5 * kDegree, 1 * kDegree);
  const MapRegistration registration(map, MapRegistrationOptions());
  const RegistrationResult result =
      registration.Register(InWorld(structure, truth), wide, CameraInWorld(truth));
  EXPECT_NE(result.lock, MapLock::kLocked) << "margin " << result.margin;
}

TEST(MapRegistrationTest, TooLittleStructureIsReported) {
  std::mt19937 rng(5);
  std::vector<Eigen::Vector3d> structure = StreetStructure(40, 0, rng);
  structure.resize(100);
  const MapRegistration registration(Street(true), MapRegistrationOptions());
  const RegistrationResult result = registration.Register(InWorld(structure, Rigid3d()),
                                                          DefaultPrior(), CameraInWorld(Rigid3d()));
  EXPECT_EQ(result.lock, MapLock::kSearching);
  EXPECT_NE(result.reason.find("too little structure"), std::string::npos);
}

TEST(MapRegistrationTest, UpComesFromTheGroundPlanes) {
  const MapRegistration registration(Street(false), MapRegistrationOptions());
  EXPECT_NEAR((registration.UpDirection(Eigen::Vector3d(0.1, -1, 0)) - kUp).norm(), 0.0, 1e-12);
  PlaneMap facades_only = Street(false);
  facades_only.planes.erase(facades_only.planes.begin());
  const MapRegistration no_ground(facades_only, MapRegistrationOptions());
  const Eigen::Vector3d hint = Eigen::Vector3d(0.1, -1, 0).normalized();
  EXPECT_NEAR((no_ground.UpDirection(hint) - hint).norm(), 0.0, 1e-12);
}

TEST(MapRegistrationTest, OptionsAreChecked) {
  MapRegistrationOptions options;
  options.max_dof_sigma = 0;
  EXPECT_THROW(options.Check(), OptionsError);
  options = MapRegistrationOptions();
  options.min_inlier_ratio = 1.5;
  EXPECT_THROW(options.Check(), OptionsError);
}

}  // namespace
}  // namespace planeloc
