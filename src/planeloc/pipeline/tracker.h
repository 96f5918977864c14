// Stereo visual odometry of the ORB-SLAM2 class with loop closing off.
//
// Per frame: ORB + stereo features -> constant-velocity prediction and guided search against
// the previous frame (fallback: the reference keyframe with a wider window) -> pose-only
// optimization -> local-map search over covisible keyframes -> pose-only optimization ->
// keyframe decision -> (keyframe) new stereo points, point culling, local window BA.
// On loss the tracker re-initializes from the frame's stereo at the predicted pose and goes on.
//
// Threads: feature extraction uses TBB inside features/; the local BA runs on a worker thread
// scheduled by a BaScheduler (deferral, lag bound, stale results), or in line when
// options.deterministic (bit-identical runs). A result applies only to the keyframes and points
// that were not moved since its window was built (BaCounts). The map lock's side (registrations,
// corrections, the settling after a lock) is defined in tracker_lock.cc.
#pragma once

#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/features/orb_extractor.h"
#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/pipeline/ba_job.h"
#include "planeloc/pipeline/ba_scheduler.h"
#include "planeloc/pipeline/frame_stats.h"
#include "planeloc/pipeline/job_worker.h"
#include "planeloc/pipeline/settings.h"
#include "planeloc/prior/cloud_surfaces.h"
#include "planeloc/prior/map_cloud_index.h"
#include "planeloc/prior/map_lock.h"
#include "planeloc/prior/plane_association.h"
#include "planeloc/prior/plane_evidence.h"
#include "planeloc/prior/window_planes.h"
#include "planeloc/tracking/frame.h"
#include "planeloc/tracking/map.h"

namespace planeloc {

struct TrackResult {
  Rigid3d world_from_cam;  // in the frame of the initial pose
  FrameStats stats;
};

// What a viewer draws of the last tracked frame (Tracker::DescribeLastFrame).
struct TrackedFrameView {
  int frame = -1;  // the frame the image belongs to; -1 before the first frame with images
  cv::Mat left;    // rectified grey left image (shared with the tracker: do not write to it)
  // The keypoints matched to a map point (level-0 pixels), and for each the map plane its map
  // point lies on (fixed association band), -1 for none. Empty unless the frame was tracked.
  std::vector<cv::Point2f> tracked;
  std::vector<int> tracked_plane;
  std::vector<int> disabled_planes;  // ids of the map planes disabled so far
  // What the run has learned about each plane so far (PlaneEvidence::Summarize), when asked for
  // and the run records plane evidence (--map-update); empty otherwise.
  std::vector<PlaneUpdate> plane_updates;
};

class Tracker {
 public:
  // `world_from_cam_initial`: pose of the first frame; the trajectory is expressed in its frame.
  // `plane_map`: LiDAR planes in that same frame (the map frame): map points on them get
  // point-to-plane residuals in the local BA (options.ba.lambda); without it the BA is visual.
  // `start_prior`: how well world_from_cam_initial is known in the map frame; unless exact, the
  // run registers its structure to the plane map (map lock) before it uses the planes, and moves
  // its map into the map frame when it locks.
  // `map_cloud`: the LiDAR map's points in that frame (`--prior depth`, or `hybrid` with
  // `plane_map`): each tracked frame's pose is refined with the depth-to-map residual
  // (prior/depth_prior.h, options.depth) and the window points on the cloud's flat patches get
  // point-to-plane residuals (prior/cloud_surfaces.h); with a plane map only once it is locked.
  // Without a plane map and a cloud the tracker is visual odometry.
  Tracker(const StereoCamera& camera, const TrackerOptions& options,
          const Rigid3d& world_from_cam_initial = Rigid3d::Identity(),
          const PlaneMap* plane_map = nullptr, const StartPrior& start_prior = {},
          std::shared_ptr<const MapCloudIndex> map_cloud = nullptr);
  ~Tracker();
  Tracker(const Tracker&) = delete;
  Tracker& operator=(const Tracker&) = delete;

  // Extracts features from a rectified grey pair and tracks them.
  TrackResult Track(const cv::Mat& left, const cv::Mat& right, double timestamp);
  // The features Track extracts from a rectified grey pair. Const and thread-safe: a caller may
  // extract the next frame while the current one is tracked (run_sequence.cc).
  StereoFeatures ExtractFeatures(const cv::Mat& left, const cv::Mat& right) const;
  // Tracks already extracted features (`ms_extract` is reported in the stats).
  TrackResult TrackFeatures(StereoFeatures features, double timestamp, double ms_extract = 0);
  // A frame without images: the motion model's pose, no map change.
  TrackResult SkipFrame(double timestamp);
  // Waits for a running BA and applies it (call at the end of a sequence).
  void Finish();

  const SparseMap& map() const { return map_; }
  // The last frame given images, its tracked keypoints and the planes they lie on. Costs a plane
  // lookup per tracked point: call it for the frames a viewer shows, not for every frame.
  // `with_plane_updates`: also summarize the plane evidence (a fit per plane: not every frame).
  TrackedFrameView DescribeLastFrame(bool with_plane_updates = false) const;
  // Map-frame corrections applied so far (registration locks).
  const std::vector<LockEvent>& lock_events() const { return lock_events_; }
  // kLocked without a plane map.
  MapLock map_lock() const { return locker_ ? locker_->state() : MapLock::kLocked; }
  // Registration attempts before the lock and why those that changed nothing did not
  // (MapLocker::refusals); none without a plane map.
  int lock_attempts() const { return locker_ ? locker_->attempts_before_lock() : 0; }
  std::map<std::string, int> lock_refusals() const {
    return locker_ ? locker_->refusals() : std::map<std::string, int>{};
  }
  const OrbExtractor& extractor() const { return extractor_; }
  const BaCounts& ba_counts() const { return ba_counts_; }
  // Map moves by the planes' consensus on the trajectory's offset (Planes.trajectoryConsensus).
  int consensus_corrections() const { return consensus_corrections_; }
  const TrackerOptions& options() const { return options_; }
  // With options.record_plane_evidence and a plane map: what the run learned about each plane;
  // nullptr otherwise.
  const PlaneEvidence* plane_evidence() const { return evidence_.get(); }

 private:
  // Start of a frame: applies the workers' finished results (waits for a BA overdue by
  // LocalBA.maxLagFrames) and submits a deferred BA.
  void CatchUpWithWorkers(FrameStats& stats, std::chrono::steady_clock::time_point track_start);
  // First frame, or loss: the frame starts (again) from its own stereo at the predicted pose.
  void RestartFromStereo(Frame& frame, const Rigid3d& predicted, FrameStats& stats);
  bool NeedKeyframe(const Frame& frame, int inliers) const;
  // Local mapping idle (ORB-SLAM2's AcceptKeyFrames): no BA running, queued, waiting to be
  // applied or deferred. Always true in deterministic mode.
  bool MappingIdle() const;
  // Inserts the keyframe and runs the mapping steps; fills ms_ba / reprojection stats.
  void InsertKeyframe(Frame& frame, FrameStats& stats);
  // Point fusion, keyframe culling and forgetting after keyframe `keyframe_id` was inserted.
  void MaintainMap(int keyframe_id);
  // The keyframe's BA window with its snapshot; std::nullopt (counted as empty) without
  // observations.
  // With Planes.trajectoryConsensus, a window whose planes agree (in this and the previous
  // window) that the trajectory sits off the map first moves the map by that offset
  // (ApplyCorrection; `current` moves with it) and is then built again.
  std::optional<BaJob> MakeBaJob(int keyframe_id, FrameStats& stats, Frame* current);
  // Planes.trajectoryConsensus: when the planes of this window and the previous one agree that
  // the trajectory sits off the map (PlaneAssociator::trajectory_offset of the closed records),
  // moves the map by that offset (`current` with it) and returns true.
  bool MoveMapByPlaneConsensus(FrameStats& stats, Frame* current);
  // Adds the window's points to the plane evidence (options.record_plane_evidence).
  void RecordEvidence(int keyframe_id, const WindowProblem& problem,
                      const WindowPointEstimates& estimates);
  // Builds the keyframe's BA window and hands it to the worker (threaded mode).
  void SubmitBa(int keyframe_id, FrameStats& stats, Frame* current);
  // Submits the deferred keyframe's BA once the worker is idle.
  void SubmitDeferredBa(FrameStats& stats);
  void ApplyBaResults(FrameStats& stats, bool wait);
  // Starts the map lock's registration when one is due after keyframe `keyframe_id` (on the
  // registration worker, or in line in deterministic mode).
  void StartRegistration(int keyframe_id);
  // No registration queued, running or finished and not yet applied.
  bool RegistrationIdle();
  // Applies a finished registration: its correction moves the segment (and `current`) into the
  // map frame.
  void ApplyLockResults(FrameStats& stats, Frame* current, bool wait);
  // A lock or re-registration (`from_lock`) also restarts the planes' bias statistics and is
  // logged as a lock event; a consensus correction keeps them (they were recorded beyond the
  // offset the planes agreed on).
  void ApplyCorrection(const MapCorrection& correction, Frame* current, int frame_id,
                       bool from_lock = true);
  // Moves the keyframes and points of the correction's segment, the last and current frame.
  void MoveSegment(const MapCorrection& correction, Frame* current);
  // The settling after a lock (bias statistics restarted, the lock's covariance) and its event.
  void LockBookkeeping(const MapCorrection& correction, int frame_id);
  Rigid3d PredictPose() const;
  // The depth prior: the frame's pose from its ORB inliers and the map cloud's depth residuals.
  void RefineWithMapDepth(const DenseDisparity& disparity, Frame& frame, FrameStats& stats);
  double CloseDepth() const { return options_.close_depth_baselines * camera_.baseline; }

  StereoCamera camera_;
  TrackerOptions options_;  // options_.ba.lambda is 1 (visual BA) without plane map and patches
  std::unique_ptr<PlaneAssociator> planes_;
  std::unique_ptr<PlaneEvidence> evidence_;  // with planes_ and options.record_plane_evidence
  OrbExtractor extractor_;
  SparseMap map_;
  std::unique_ptr<BaScheduler> ba_scheduler_;       // threaded mode
  std::unique_ptr<MapLocker> locker_;               // with a plane map
  std::shared_ptr<const MapCloudIndex> map_cloud_;  // with the depth prior
  std::unique_ptr<CloudSurfaces> cloud_surfaces_;   // with it and DepthPrior.windowSurfaces
  // Threaded mode with a plane map: runs the locker's registrations. In line (deterministic), a
  // finished registration waits in inline_registration_ until applied.
  std::unique_ptr<JobWorker<RegistrationJob>> registration_worker_;
  std::optional<RegistrationJob> inline_registration_;
  std::vector<LockEvent> lock_events_;
  // The trajectory offset the planes agreed on in the previous window (Planes.
  // trajectoryConsensus), and the corrections it caused.
  std::optional<Eigen::Vector3d> previous_consensus_;
  int consensus_corrections_ = 0;
  // Keyframe id from which plane bias statistics stop allowing for the last lock's error; -1: none.
  int settle_until_keyframe_id_ = -1;
  // After a lock (partial or full): the next window spans the segment, no anchor, its oldest
  // keyframe fixed.
  bool lock_window_pending_ = false;
  BaCounts ba_counts_;
  Rigid3d cam_from_world_initial_;

  int next_frame_id_ = 0;
  std::optional<Frame> last_frame_;
  // last frame relative to its reference keyframe: re-anchors it when BA moves the keyframe
  Rigid3d last_from_reference_;
  std::optional<Rigid3d> velocity_;  // current_from_last of the last tracked step
  int reference_keyframe_id_ = -1;
  int last_keyframe_frame_id_ = 0;
  std::vector<int> recent_point_ids_;
  bool lost_before_ = false;
  int frames_skipped_ = 0;             // frames without images since last_frame_
  std::vector<cv::Mat> left_pyramid_;  // of the frame being tracked, for the crease check
};

}  // namespace planeloc
