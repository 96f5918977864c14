#include "planeloc/prior/lock_fusion.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "planeloc/prior/street_for_test.h"

namespace planeloc {
namespace {

using namespace street_for_test;  // NOLINT(build/namespaces): the fixture

// The camera's displacement by a correction, in the street's axes: the street runs along +z, the
// lateral axis is +x (up is -y).
Eigen::Vector3d CameraMove(const Rigid3d& map_from_world, const Rigid3d& world_from_camera) {
  const Eigen::Vector3d camera = world_from_camera.translation;
  return map_from_world * camera - camera;
}

TEST(LockFusionTest, StraightStreetPartialLockLeavesAlongTrackUntouched) {
  // The start is 0.8 m off sideways, 0.2 m in height, 0.7 m along the street and 2 deg in
  // heading. Road and parallel facades observe all of that but the along-track part.
  std::mt19937 rng(7);
  const Rigid3d truth = TrueMapFromWorld(2.0, {0.8, 0.2, 0.7});
  const MapRegistration registration(Street(false), MapRegistrationOptions());
  const Rigid3d camera = CameraInWorld(truth);
  const RegistrationResult result =
      registration.Register(InWorld(StreetStructure(40, 0, rng), truth), DefaultPrior(), camera);
  ASSERT_EQ(result.lock, MapLock::kPartial) << result.reason;
  const Matrix6d current =
      PriorCovarianceAtCamera(DefaultPrior(), camera.translation, result.vehicle_axes);
  const FusedCorrection fused = FuseRegistration(result, current, 3.0, 0.0);
  ASSERT_TRUE(fused.accepted);
  EXPECT_FALSE(fused.registered_dofs[kAlongTrack]);

  const Eigen::Vector3d moved = CameraMove(fused.map_from_world, camera);
  const Eigen::Vector3d wanted = CameraMove(truth, camera);
  // Along-track: untouched to the millimetre (the truth would move it by 0.7 m + the yaw's share).
  EXPECT_LT(std::abs(moved.z()), 1e-3);
  EXPECT_GT(std::abs(wanted.z()), 0.6);
  // Lateral and vertical: where the truth puts the camera (3 cm point noise; measured 0.4 cm
  // lateral, 0.1 cm vertical).
  EXPECT_NEAR(moved.x(), wanted.x(), 0.03);
  EXPECT_NEAR(moved.y(), wanted.y(), 0.03);
  // Heading: a point 30 m ahead of the camera lands where the truth puts it sideways.
  const Eigen::Vector3d ahead = camera * Eigen::Vector3d(0, 0, 30);
  EXPECT_NEAR((fused.map_from_world * ahead).x(), (truth * ahead).x(), 0.05);
}

// A registration that observes every DoF with the given sigma (metres; radians), proposing `z`.
RegistrationResult Observed(const Vector6d& z, double sigma) {
  RegistrationResult result;
  result.constrained.fill(true);
  result.correction_at_camera = z;
  result.information_at_camera = Matrix6d::Identity() / (sigma * sigma);
  return result;  // vehicle axes = world axes, camera at the origin
}

TEST(LockFusionTest, EqualConfidenceMeetsHalfWay) {
  // Registration and current estimate both 0.1 m sure: the fused shift is half the proposed one,
  // the innovation's sigma sqrt(0.1^2 + 0.1^2).
  Vector6d z = Vector6d::Zero();
  z(kLateral) = 0.2;
  const FusedCorrection fused =
      FuseRegistration(Observed(z, 0.1), Matrix6d::Identity() * 0.01, 3.0, 0.0);
  ASSERT_TRUE(fused.accepted);
  EXPECT_NEAR(fused.applied(kLateral), 0.1, 1e-9);
  EXPECT_NEAR(fused.innovation_sigma(kLateral), std::sqrt(0.02), 1e-9);
  EXPECT_NEAR(fused.worst_sigmas, 0.2 / std::sqrt(0.02), 1e-6);
  EXPECT_EQ(fused.worst_dof, kLateral);
  EXPECT_NEAR(fused.map_from_world.translation.y(), 0.1, 1e-9);  // world axes: y is lateral here
  // Fused variance 0.005 m^2 in the lateral direction.
  EXPECT_NEAR(fused.camera_position_covariance(1, 1), 0.005, 1e-9);
}

TEST(LockFusionTest, ConfidentEstimateIsNotReplacedByANoisierRegistration) {
  // Current estimate 2 cm, registration 20 cm: the estimate moves by 1/101 of the proposal.
  Vector6d z = Vector6d::Zero();
  z(kVertical) = 0.3;
  const FusedCorrection fused =
      FuseRegistration(Observed(z, 0.2), Matrix6d::Identity() * 0.0004, 3.0, 0.0);
  ASSERT_TRUE(fused.accepted);
  EXPECT_NEAR(fused.applied(kVertical), 0.3 * 0.0004 / (0.0004 + 0.04), 1e-9);
}

TEST(LockFusionTest, GateRefusesAnInnovationBeyondThreeSigma) {
  // Innovation sigma sqrt(0.02) = 0.141 m: 0.40 m is 2.83 sigma, 0.45 m is 3.18 sigma.
  for (const auto& [shift, accepted] : {std::pair{0.40, true}, std::pair{0.45, false}}) {
    Vector6d z = Vector6d::Zero();
    z(kLateral) = shift;
    const FusedCorrection fused =
        FuseRegistration(Observed(z, 0.1), Matrix6d::Identity() * 0.01, 3.0, 0.0);
    EXPECT_EQ(fused.accepted, accepted) << shift;
  }
}

TEST(LockFusionTest, AChangeWithinTheRegistrationsOwnNoiseIsHeld) {
  // Registration sigma 0.1 m, current estimate 2 m: 0.12 m is 1.2 of the registration's sigmas
  // (held at min_sigmas 1.5), 0.2 m is 2 (applied, almost whole).
  for (const auto& [shift, applied] : {std::pair{0.12, 0.0}, std::pair{0.2, 0.2 * 4 / 4.01}}) {
    Vector6d z = Vector6d::Zero();
    z(kLateral) = shift;
    const FusedCorrection fused =
        FuseRegistration(Observed(z, 0.1), Matrix6d::Identity() * 4.0, 3.0, 1.5);
    ASSERT_TRUE(fused.accepted);
    EXPECT_NEAR(fused.applied(kLateral), applied, 1e-6) << shift;
    EXPECT_EQ(fused.changed_dofs[kLateral], applied != 0.0) << shift;
    EXPECT_TRUE(fused.registered_dofs[kLateral]);
  }
}

TEST(LockFusionTest, CoupledDofTakeTheRegistrationsMarginal) {
  // Along-track and pitch coupled (a plane seen at an angle): information [[1, 2], [2, 8]] on
  // (along, pitch), along-track not registered and proposed at 1.0 m (a value the search prior
  // set). The pitch estimate is the proposal itself, 0.01, not shifted through the coupling; its
  // variance is the marginal 1 / (8 - 2 * 2 / 1) = 0.25 (not the conditional 1/8). Against a
  // current pitch variance of 0.25 the fused pitch is half of it: 0.005 (0.0067 with 1/8).
  RegistrationResult result;
  result.constrained.fill(true);
  result.constrained[kAlongTrack] = false;
  result.information_at_camera = Matrix6d::Identity() * 1e4;
  result.information_at_camera(kAlongTrack, kAlongTrack) = 1.0;
  result.information_at_camera(kPitch, kPitch) = 8.0;
  result.information_at_camera(kAlongTrack, kPitch) = 2.0;
  result.information_at_camera(kPitch, kAlongTrack) = 2.0;
  result.correction_at_camera(kAlongTrack) = 1.0;
  result.correction_at_camera(kPitch) = 0.01;
  Matrix6d current = Matrix6d::Identity() * 1e4;  // 100 m, 100 rad: no knowledge ...
  current(kPitch, kPitch) = 0.25;                 // ... but of pitch
  const FusedCorrection fused = FuseRegistration(result, current, 3.0, 0.0);
  EXPECT_NEAR(fused.registered(kPitch), 0.01, 1e-12);
  EXPECT_EQ(fused.applied(kAlongTrack), 0.0);
  EXPECT_NEAR(fused.applied(kPitch), 0.005, 1e-5);
}

TEST(LockFusionTest, AHeldDofHoldsWhatMovesWithIt) {
  // Structure 30 m behind the camera sees height and pitch only together: h = vertical + 30 pitch,
  // sigma 1 cm, plus a weak direct view of each (vertical 0.1 m, pitch 0.002 rad). Marginal sigmas
  // 0.0520 m and 0.00172 rad; the conditional sigma of vertical given pitch is 0.00995 m.
  RegistrationResult result;
  result.constrained.fill(true);
  result.information_at_camera = Matrix6d::Identity() * 1e6;
  result.information_at_camera(kVertical, kVertical) = 1e4 + 1e2;
  result.information_at_camera(kVertical, kPitch) = 3e5;
  result.information_at_camera(kPitch, kVertical) = 3e5;
  result.information_at_camera(kPitch, kPitch) = 9e6 + 1 / (0.002 * 0.002);
  Matrix6d current = Matrix6d::Identity() * 100.0;  // the start prior: no knowledge
  // Vertical -0.085 m (1.64 marginal sigmas: significant on its own) with pitch 0.0025 rad (1.46:
  // held): the structure's height barely changes (-0.085 + 30 * 0.0025 = -0.01 m), so nothing
  // moves. The marginal alone moved the camera down 8.5 cm and the structure with it.
  result.correction_at_camera(kVertical) = -0.085;
  result.correction_at_camera(kPitch) = 0.0025;
  FusedCorrection fused = FuseRegistration(result, current, 3.0, 1.5);
  ASSERT_TRUE(fused.accepted);
  EXPECT_FALSE(fused.changed_dofs[kPitch]);
  EXPECT_FALSE(fused.changed_dofs[kVertical]);
  EXPECT_EQ(fused.applied(kVertical), 0.0);
  EXPECT_NEAR(fused.registered(kVertical), -0.085, 1e-12);  // the stats keep the marginal
  // Vertical -0.12 m with the same pitch: given pitch 0, the height change the structure asks
  // for is -0.12 + 0.0743 = -0.0457 m (4.6 conditional sigmas), applied almost whole.
  result.correction_at_camera(kVertical) = -0.12;
  fused = FuseRegistration(result, current, 3.0, 1.5);
  ASSERT_TRUE(fused.accepted);
  EXPECT_FALSE(fused.changed_dofs[kPitch]);
  EXPECT_TRUE(fused.changed_dofs[kVertical]);
  EXPECT_NEAR(fused.applied(kVertical), -0.0457, 1e-3);
}

TEST(LockFusionTest, HeadingUncertaintyAtThePivotIsLateralAtTheCamera) {
  // 1 deg of heading 40 m behind the camera: 40 * 1 deg = 0.698 m of lateral sigma, nothing
  // along-track or vertical.
  const RegistrationPrior prior =
      RegistrationPrior::FromSigmas(Eigen::Vector3d::Zero(), kUp, 0.0, 0.0, 1.0 * kDegree, 0.0);
  Eigen::Matrix3d axes;
  axes.row(0) = Eigen::Vector3d(0, 0, 1).transpose();             // along: +z
  axes.row(1) = kUp.cross(Eigen::Vector3d(0, 0, 1)).transpose();  // lateral
  axes.row(2) = kUp.transpose();
  const Matrix6d at_camera = PriorCovarianceAtCamera(prior, {0, 0, 40}, axes);
  EXPECT_NEAR(std::sqrt(at_camera(kLateral, kLateral)), 40 * kDegree, 1e-9);
  EXPECT_NEAR(at_camera(kAlongTrack, kAlongTrack), 0.0, 1e-12);
  EXPECT_NEAR(at_camera(kVertical, kVertical), 0.0, 1e-12);
  EXPECT_NEAR(std::sqrt(at_camera(kYaw, kYaw)), 1.0 * kDegree, 1e-12);
}

}  // namespace
}  // namespace planeloc
