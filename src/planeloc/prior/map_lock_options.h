// What a user sets about the map lock: how well the start pose is known (--init-sigma) and the
// lock's options. Apart from the state machine (map_lock.h), so that the options table and the
// public API need not see it.
#pragma once

#include <Eigen/Core>
#include <string>

#include "planeloc/io/plane_map.h"
#include "planeloc/prior/map_registration.h"

namespace planeloc {

// How well the start pose is known (planeloc run --init-sigma "S_XY S_Z S_YAW_DEG").
struct StartPrior {
  double sigma_horizontal = 0.0;  // metres
  double sigma_vertical = 0.0;    // metres
  double sigma_yaw_deg = 0.0;     // degrees of heading
  bool Exact() const {
    return sigma_horizontal == 0.0 && sigma_vertical == 0.0 && sigma_yaw_deg == 0.0;
  }
  // What the registration can search at its grid's resolution (+-3 sigma): 200 shift cells of
  // 0.31 m, vertical bins of 5 cm, 91 headings of 1 degree. Wider priors are refused.
  static constexpr double kMaxSigmaHorizontal = 10.0;  // metres
  static constexpr double kMaxSigmaVertical = 2.0;     // metres
  static constexpr double kMaxSigmaYawDeg = 15.0;      // degrees
  void Check() const;  // throws OptionsError: finite, >= 0 and within the maxima
};

// A warning when the plane map cannot resolve the start prior: the start is far from every plane
// of the map (outside the mapped area), or the prior is wider than the map. Empty otherwise.
std::string StartPriorWarning(const PlaneMap& planes, const Eigen::Vector3d& start_position,
                              const StartPrior& prior);

struct MapLockOptions {
  MapRegistrationOptions registration;
  int attempt_every_keyframes = 2;   // while not locked, a registration every N keyframes
  int structure_keyframes = 40;      // structure: points of the segment's last N keyframes ...
  double max_point_distance = 20.0;  // ... within this distance (m) of their reference keyframe
  int min_point_observations = 2;    // ... seen by this many keyframes
  double disparity_sigma_px = 0.2;   // depth sigma of a point: z^2 / (f b) * this
  // Prior growth with the distance driven since the prior's pivot (visual odometry drift).
  double drift_fraction = 0.01;  // metres per metre, horizontal
  double drift_yaw_deg_per_100m = 0.3;
  // Prior of the registered DoF after a partial lock (for the attempt that completes it).
  double partial_sigma_lateral = 0.3;   // metres
  double partial_sigma_vertical = 0.2;  // metres
  double partial_sigma_yaw_deg = 1.0;
  // Prior after a loss: added (in quadrature) to the current one at the predicted pose.
  double lost_sigma_horizontal = 1.0;  // metres
  double lost_sigma_vertical = 0.3;    // metres
  double lost_sigma_yaw_deg = 3.0;
  // After a correction, plane bias statistics allow for the lock's position uncertainty during
  // this many keyframes (the window BA then pulls the trajectory onto the planes).
  int settle_keyframes = 30;
  // Once locked: a re-registration every N keyframes (0: never), with a tight prior around the
  // current estimate. The window BA only sees points within the association band of a plane
  // (Planes.maxDistance), so an error beyond it (a lock onto a wrong plane of the map, drift
  // through a stretch without planes) is never pulled back by the BA; the registration, which
  // searches, can. Its correction is applied only when it moves the current camera by more than
  // max(min_recorrection, recorrection_sigmas x its sigma) in a registered DoF, or turns it by
  // more than min_recorrection_deg: smaller errors are the BA's.
  // Off by default (0): with a wrong map (bench_wrong_map.sh, small seed 21: planes rotated by 2
  // deg, or a map from noisy poses) it accepted 4-5 deg / 2-3.5 m corrections far outside its
  // own prior and the ATE went from 0.06 to 0.52 m. It needs a consistency test against the
  // prior (Mahalanobis distance of the correction) before it can be on.
  int maintain_every_keyframes = 0;
  double maintain_sigma_horizontal = 0.5;  // metres
  double maintain_sigma_vertical = 0.4;    // metres
  double maintain_sigma_yaw_deg = 2.0;
  double min_recorrection = 0.15;    // metres
  double recorrection_sigmas = 1.5;  // of the (inflated, see noise_inflation) DoF sigma
  double min_recorrection_deg = 1.0;
  // A registration is evidence fused with the current pose (prior/lock_fusion.h); one whose
  // innovation exceeds this many standard deviations in a registered DoF is refused.
  double max_correction_sigmas = 3.0;
  // ... and a registered DoF whose change is within this many of the registration's own sigmas
  // keeps the current estimate (the window BA's plane residuals refine it without a jump).
  double min_correction_sigmas = 1.5;
  void Check() const;
};

}  // namespace planeloc
