// The map-lock state machine of a run that starts from a coarse pose: when to register the
// tracker's structure to the plane map (prior/map_registration.h), with which prior, and what
// correction the tracker must apply to its map.
//
//   searching --(5 DoF registered, along-track unobserved)--> partial --(all 6)--> locked
//   any state --(tracking lost, map re-initialized)--> searching (a new segment, inflated prior)
//
// Before the lock the run is visual odometry in the start pose's frame and the BA uses no plane
// residual (a wrong association from a coarse pose would pull the map towards the wrong plane).
// A registration runs on the MapLocker's own worker thread (or in line when deterministic) over
// a copy of the structure; its correction applies to the keyframes and points of the current
// segment, which a later correction or a loss never touches twice.
#pragma once

#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/prior/lock_fusion.h"
#include "planeloc/prior/map_registration.h"
#include "planeloc/tracking/map.h"

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

// A correction to apply: p_map = map_from_world * p for the keyframes with id >= first_keyframe
// and the points they created.
struct MapCorrection {
  Rigid3d map_from_world;
  int first_keyframe_id = 0;
  // How well the correction places the current camera in the map (m^2, map axes): what a plane's
  // points may sit off it right after the lock without the plane being wrong.
  Eigen::Matrix3d camera_position_covariance = Eigen::Matrix3d::Zero();
  bool recorrection = false;  // by a re-registration while locked
};

// One registration attempt, as reported in the stats.
struct RegistrationReport {
  int keyframe_id = 0;  // the attempt's last keyframe
  MapLock lock_before = MapLock::kSearching;
  MapLock lock_after = MapLock::kSearching;
  bool maintenance = false;  // a re-registration while locked
  bool applied = false;      // its correction was applied
  RegistrationResult result;
  std::optional<FusedCorrection> fusion;  // when the result was a lock worth applying
  std::string ToJson() const;
};

class MapLocker {
 public:
  // `world_from_cam_initial`: the start pose (the prior's mean); an exact start begins locked.
  // `threaded`: registrations on a worker thread; otherwise in line (bit-identical runs).
  MapLocker(const PlaneMap& planes, const MapLockOptions& options, const StartPrior& start,
            const Rigid3d& world_from_cam_initial, bool threaded);
  ~MapLocker();
  MapLocker(const MapLocker&) = delete;
  MapLocker& operator=(const MapLocker&) = delete;

  MapLock state() const { return state_; }
  // Plane residuals in the BA: only once the map frame is known.
  bool PlanesActive() const { return state_ != MapLock::kSearching; }

  // No attempt pending, running or finished and not yet taken: a correction of the map applied
  // now (Planes.trajectoryConsensus) cannot be undone by one computed before it.
  bool Idle();
  // After keyframe `keyframe_id` was inserted: starts an attempt when one is due.
  void OnKeyframe(const SparseMap& map, int keyframe_id, const StereoCamera& camera);
  // A finished attempt (in line: the one OnKeyframe just ran). `wait` blocks for a running one.
  // The state is updated; the report and the correction (if any) are returned.
  std::optional<std::pair<RegistrationReport, std::optional<MapCorrection>>> TakeResult(
      bool wait = false);
  // Tracking was lost and the map re-initialized at `world_from_cam` (the motion model's pose):
  // the next keyframe starts a new segment, searched with an inflated prior.
  void OnLoss(const Rigid3d& world_from_cam, int next_keyframe_id);

 private:
  struct Job {
    int segment = 0;
    int keyframe_id = 0;
    int first_keyframe_id = 0;  // oldest keyframe whose points are in `points`
    bool maintenance = false;
    std::vector<RegistrationPoint> points;
    RegistrationPrior prior;
    Rigid3d world_from_camera;
    std::optional<RegistrationResult> result;
  };
  RegistrationPrior CurrentPrior(const Eigen::Vector3d& camera_in_world) const;
  // Whether a re-registration's correction is beyond what the window BA pulls back.
  bool SignificantRecorrection(const RegistrationResult& result,
                               const FusedCorrection& fusion) const;
  void Run(std::stop_token stop);
  std::optional<std::pair<RegistrationReport, std::optional<MapCorrection>>> Finish(Job job);

  MapLockOptions options_;
  MapRegistration registration_;
  MapLock state_ = MapLock::kSearching;
  Eigen::Vector3d up_in_world_;
  // The prior of the current segment: pivot, vehicle axes at the pivot and sigmas.
  Eigen::Vector3d pivot_in_world_, forward_in_world_;
  double sigma_along_, sigma_lateral_, sigma_vertical_, sigma_yaw_;  // metres, radians
  int segment_ = 0;
  int segment_first_keyframe_ = 0;
  int keyframes_since_attempt_ = 0;

  // Worker (threaded mode): one job at a time.
  std::mutex mutex_;
  std::condition_variable_any wake_;
  std::condition_variable done_;
  std::optional<Job> pending_, finished_;
  bool running_ = false;
  std::optional<Job> inline_finished_;
  std::jthread thread_;  // last member: started after the state above exists
};

}  // namespace planeloc
