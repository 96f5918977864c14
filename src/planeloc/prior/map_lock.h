// The map-lock state machine of a run that starts from a coarse pose: when to register the
// tracker's structure to the plane map (prior/map_registration.h), with which prior, and what
// correction the tracker must apply to its map.
//
//   searching --(5 DoF registered, along-track unobserved)--> partial --(all 6)--> locked
//   any state --(tracking lost, map re-initialized)--> searching (a new segment, inflated prior)
//
// Before the lock the run is visual odometry in the start pose's frame and the BA uses no plane
// residual (a wrong association from a coarse pose would pull the map towards the wrong plane).
// A registration runs on the pipeline's worker (or in line when deterministic) over a copy of
// the structure (RegistrationJob); its correction applies to the keyframes and points of the
// current segment, which a later correction or a loss never touches twice.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/prior/lock_fusion.h"
#include "planeloc/prior/map_lock_options.h"
#include "planeloc/prior/map_registration.h"
#include "planeloc/tracking/map.h"

namespace planeloc {

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

// One registration attempt's input, copied out of the map so that it can run on another thread
// (MapLocker::Run), and its result.
struct RegistrationJob {
  int segment = 0;
  int keyframe_id = 0;
  int first_keyframe_id = 0;  // oldest keyframe whose points are in `points`
  bool maintenance = false;
  std::vector<RegistrationPoint> points;
  RegistrationPrior prior;
  Rigid3d world_from_camera;
  std::optional<RegistrationResult> result;
};

// The map lock's state machine: when to register the run's structure to the plane map, with
// what prior, and what a finished registration changes. It holds no thread: the caller runs the
// jobs it makes (MapLocker::Run), in line or on a worker, and hands them back to Finish.
class MapLocker {
 public:
  // `world_from_cam_initial`: the start pose (the prior's mean); an exact start begins locked.
  MapLocker(const PlaneMap& planes, const MapLockOptions& options, const StartPrior& start,
            const Rigid3d& world_from_cam_initial);

  MapLock state() const { return state_; }
  // Plane residuals in the BA: only once the map frame is known.
  bool PlanesActive() const { return state_ != MapLock::kSearching; }

  // After keyframe `keyframe_id` was inserted: whether an attempt is due now. If the caller
  // cannot run it (a registration still running), the next keyframe asks again.
  bool AttemptDue(int keyframe_id);
  // The due attempt's job: the structure of the segment's last keyframes and the current prior.
  RegistrationJob MakeJob(const SparseMap& map, int keyframe_id, const StereoCamera& camera);
  // Runs the registration of a job (thread-safe: reads only the plane map). A registration that
  // throws is reported as failed in the job's result.
  void Run(RegistrationJob& job) const;
  // A finished job: the state is updated; the report and the correction (if any) are returned.
  // std::nullopt for a job without result, or of a segment that a loss has ended since.
  std::optional<std::pair<RegistrationReport, std::optional<MapCorrection>>> Finish(
      RegistrationJob job);
  // Attempts finished before the run was locked (maintenance excluded), and why those that
  // changed nothing did not: each reason in its category (numbers left out), with its count.
  int attempts_before_lock() const { return attempts_before_lock_; }
  const std::map<std::string, int>& refusals() const { return refusals_; }
  // Tracking was lost and the map re-initialized at `world_from_cam` (the motion model's pose):
  // the next keyframe starts a new segment, searched with an inflated prior.
  void OnLoss(const Rigid3d& world_from_cam, int next_keyframe_id);

 private:
  std::optional<std::pair<RegistrationReport, std::optional<MapCorrection>>> FinishAttempt(
      RegistrationJob job);
  RegistrationPrior CurrentPrior(const Eigen::Vector3d& camera_in_world) const;
  // Whether a re-registration's correction is beyond what the window BA pulls back.
  bool SignificantRecorrection(const RegistrationResult& result,
                               const FusedCorrection& fusion) const;

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
  int attempts_before_lock_ = 0;
  std::map<std::string, int> refusals_;
};

// A registration's reason without its numbers, to count reasons over a run: "few points on
// planes (12 of 300)" -> "few points on planes"; "refused: 3.4 sigma from the current estimate in
// lateral (limit 3.0)" -> "refused: beyond the gate in lateral".
std::string ReasonCategory(const std::string& reason);

}  // namespace planeloc
