// What a map-lock registration may change, and by how much: the registration is evidence about the
// camera's pose in the map, fused with what the run already knows (docs/map-registration.md,
// "Applying a registration").
//
// Both are expressed at the current camera, in its vehicle axes (along-track, lateral, up; shifts
// in metres, rotations in radians about the same axes), so that "a direction the planes do not
// observe" is one coordinate:
//  1. Restriction: the unobserved DoF (RegistrationResult::constrained false) keep the current
//     estimate. The registered DoF take the registration's own estimate of them with its marginal
//     covariance (the unobserved DoF as uncertain to it as to the current estimate).
//  2. Fusion: the restricted estimate and the current one are averaged, weighted by their
//     covariances (the current: the start prior grown with the distance driven, or what a partial
//     lock left).
//  3. Gate: the innovation (restricted estimate minus current estimate) must lie within
//     `max_sigmas` of its standard deviation sqrt(C_registration + C_current) in every registered
//     DoF; otherwise the registration is refused.
//  4. Significance: a registered DoF whose proposed change is within `min_sigmas` of the
//     registration's own standard deviation is held too: the registration cannot tell the
//     current estimate from its own there, and the window BA's plane residuals (which start with
//     the lock) refine it without a jump. The changed DoF then take the registration's estimate
//     conditioned on the held ones staying put (not its marginal: correlated DoF, such as height
//     and pitch seen through structure behind the camera, move together or not at all), and the
//     test is repeated until no further DoF is held.
// The correction is applied as a rotation about the current camera plus a shift of it, so a
// rotation never moves the camera along an unobserved direction.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>

#include "planeloc/geometry/lie.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/prior/map_registration.h"

namespace planeloc {

struct FusedCorrection {
  bool accepted = false;
  std::array<bool, kNumDofs> registered_dofs{};  // the DoF the registration observes
  std::array<bool, kNumDofs> changed_dofs{};     // those it changes (significant ones)
  Vector6d registered = Vector6d::Zero();        // restricted registration estimate
  Vector6d applied = Vector6d::Zero();           // fused: what the correction does
  // Standard deviation of the innovation per registered DoF (infinite for the others).
  Vector6d innovation_sigma = Vector6d::Zero();
  double worst_sigmas = 0;  // max over registered DoF of |registered| / innovation_sigma
  int worst_dof = -1;
  // p_map = map_from_world * p: a rotation about the camera plus the applied camera shift.
  Rigid3d map_from_world;
  // Fused covariance of the camera position (m^2, map axes).
  Eigen::Matrix3d camera_position_covariance = Eigen::Matrix3d::Zero();
  // The applied correction and the gate, metres and degrees (map_lock.cc, with the report).
  std::string ToJson() const;
};

// Covariance of the correction `prior` describes (pivoted at prior.pivot_in_world, world axes),
// evaluated at `camera_in_world` in the vehicle axes whose rows are `vehicle_axes`.
Matrix6d PriorCovarianceAtCamera(const RegistrationPrior& prior,
                                 const Eigen::Vector3d& camera_in_world,
                                 const Eigen::Matrix3d& vehicle_axes);

// Fuses `result` (its correction_at_camera and information_at_camera) with the current pose
// covariance `current_covariance` (same coordinates). Registered DoF: `result.constrained`.
FusedCorrection FuseRegistration(const RegistrationResult& result,
                                 const Matrix6d& current_covariance, double max_sigmas,
                                 double min_sigmas);

}  // namespace planeloc
