#include "planeloc/prior/map_registration.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

#include "planeloc/prior/street_for_test.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

using namespace street_for_test;  // NOLINT(build/namespaces): the fixture

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
