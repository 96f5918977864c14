// The tracker's side of the map lock (tracker.h): starting registrations, applying their
// corrections and the planes' trajectory consensus to the segment, and the settling after a lock.
// Split from tracker.cc, which keeps the per-frame tracking and the window BA's scheduling.
#include <optional>
#include <utility>
#include <vector>

#include "planeloc/pipeline/tracker.h"

namespace planeloc {

bool Tracker::MoveMapByPlaneConsensus(FrameStats& stats, Frame* current) {
  // With lambda = 1 the planes do not act on the trajectory (the ablation's "no plane term").
  if (!options_.planes.trajectory_consensus || options_.ba.lambda >= 1.0) return false;
  // The window BA cannot pull the trajectory back by the offset itself: its fixed anchor
  // keyframes carry the same error, and the visual terms hold the window rigidly to them. Two
  // windows in a row agreeing on the offset move the whole map by it instead, as a lock does
  // (not while a registration of the map lock runs: its correction would undo this one).
  const Eigen::Vector3d offset = planes_->trajectory_offset();
  const double tolerance = 2.0 * options_.planes.consensus_tolerance;
  if (offset.isZero()) {
    previous_consensus_.reset();
    return false;
  }
  if (!previous_consensus_ || (offset - *previous_consensus_).norm() > tolerance ||
      !RegistrationIdle()) {
    previous_consensus_ = offset;
    return false;
  }
  MapCorrection correction;
  correction.map_from_world = Rigid3d(Eigen::Quaterniond::Identity(), -offset);
  correction.first_keyframe_id = 0;
  ApplyCorrection(correction, current, stats.frame, /*from_lock=*/false);
  stats.consensus_correction = -offset;
  ++consensus_corrections_;
  previous_consensus_.reset();
  return true;
}

void Tracker::StartRegistration(int keyframe_id) {
  if (!locker_->AttemptDue(keyframe_id)) return;
  if (registration_worker_ && !registration_worker_->Idle()) return;  // the next keyframe asks
  RegistrationJob job = locker_->MakeJob(map_, keyframe_id, camera_);
  if (registration_worker_) {
    registration_worker_->Submit(std::move(job));
    return;
  }
  locker_->Run(job);
  inline_registration_ = std::move(job);
}

bool Tracker::RegistrationIdle() {
  return !inline_registration_ && (!registration_worker_ || registration_worker_->Idle());
}

void Tracker::ApplyLockResults(FrameStats& stats, Frame* current, bool wait) {
  if (!locker_) return;
  std::optional<RegistrationJob> job = std::exchange(inline_registration_, std::nullopt);
  if (!job && registration_worker_) {
    job = wait ? registration_worker_->WaitResult() : registration_worker_->TakeResult();
  }
  if (!job) return;
  auto finished = locker_->Finish(std::move(*job));
  if (!finished) return;
  const auto& [report, correction] = *finished;
  stats.registration = report.ToJson();
  if (correction) ApplyCorrection(*correction, current, stats.frame);
}

void Tracker::ApplyCorrection(const MapCorrection& correction, Frame* current, int frame_id,
                              bool from_lock) {
  const Rigid3d& map_from_world = correction.map_from_world;
  // A lock that confirms the current estimate (every registered DoF held, prior/lock_fusion.h)
  // moves nothing: BA results and crease checks in flight stay valid.
  const bool moves =
      !(map_from_world.translation.isZero(0.0) && map_from_world.rotation.vec().isZero(0.0));
  if (moves) MoveSegment(correction, current);
  if (from_lock) LockBookkeeping(correction, frame_id);
}

void Tracker::MoveSegment(const MapCorrection& correction, Frame* current) {
  const Rigid3d& map_from_world = correction.map_from_world;
  const Rigid3d world_from_map = map_from_world.Inverse();
  for (const auto& [kf_id, keyframe] : map_.keyframes()) {
    if (kf_id < correction.first_keyframe_id) continue;
    map_.SetKeyframePose(kf_id, keyframe.cam_from_world * world_from_map);
  }
  std::vector<int> moved;
  for (const auto& [id, point] : map_.points()) {
    if (point.first_keyframe_id < correction.first_keyframe_id) continue;
    moved.push_back(id);
  }
  for (const int id : moved) {
    map_.SetPointPosition(id, map_from_world * map_.point(id).point_in_world);
  }
  for (const int id : moved) map_.UpdatePointGeometry(id);
  // Velocity and pose relative to the reference keyframe are frame-free: they stay.
  if (last_frame_) last_frame_->cam_from_world = last_frame_->cam_from_world * world_from_map;
  if (current) current->cam_from_world = current->cam_from_world * world_from_map;
  if (ba_scheduler_) ba_scheduler_->OnCorrection();
}

void Tracker::LockBookkeeping(const MapCorrection& correction, int frame_id) {
  const Rigid3d& map_from_world = correction.map_from_world;
  if (planes_) {
    // Until the window BA has pulled the trajectory onto the planes, a plane's points may sit off
    // it by the lock's own error: that is no evidence against the plane.
    planes_->ResetHealth();
    if (evidence_) evidence_->Reset();
    planes_->SetTrajectoryCovariance(correction.camera_position_covariance);
    settle_until_keyframe_id_ = map_.last_keyframe_id() + options_.map_lock.settle_keyframes;
  }
  // The partial lock too: the planes then hold lateral, height and heading, and the window that
  // lets them pull the whole segment at once lowered the draws' ATE after the full lock (small 11
  // and 43; docs/experiments.md, session 39). A partial result is applied once, so at most two
  // such windows per segment.
  if (locker_->state() != MapLock::kSearching && !correction.recorrection) {
    lock_window_pending_ = true;
  }
  lock_events_.push_back({frame_id, locker_->state(), map_from_world, correction.first_keyframe_id,
                          correction.recorrection});
}

}  // namespace planeloc
