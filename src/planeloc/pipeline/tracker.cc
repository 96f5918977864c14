#include "planeloc/pipeline/tracker.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>
#include <utility>

#include "planeloc/geometry/lie.h"
#include "planeloc/optim/pose_optimizer.h"
#include "planeloc/prior/depth_prior.h"
#include "planeloc/prior/window_planes.h"
#include "planeloc/tracking/frame_tracking.h"
#include "planeloc/tracking/keyframe_rule.h"
#include "planeloc/tracking/local_mapping.h"
#include "planeloc/tracking/map_maintenance.h"
#include "planeloc/tracking/matcher.h"
#include "planeloc/tracking/triangulation.h"

namespace planeloc {
namespace {

using Clock = std::chrono::steady_clock;

double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

void RecordBaStats(const BaJob& job, const BaApplyStats& applied, FrameStats& stats) {
  stats.ba_median_reprojection_px = applied.median_reprojection_px;
  stats.ba_plane_residuals = job.result.num_plane_residuals;
  int free_keyframes = 0;
  for (const WindowKeyframe& kf : job.problem.keyframes) free_keyframes += !kf.fixed;
  stats.ba_window_keyframes = free_keyframes;
  stats.ba_fixed_keyframes = static_cast<int>(job.problem.keyframes.size()) - free_keyframes;
}

}  // namespace

Tracker::Tracker(const StereoCamera& camera, const TrackerOptions& options,
                 const Rigid3d& world_from_cam_initial, const PlaneMap* plane_map,
                 const StartPrior& start_prior, std::shared_ptr<const MapCloudIndex> map_cloud)
    : camera_(camera),
      options_(options),
      extractor_(options.orb),
      map_(ScaleModel{options.orb.scale_factor, options.orb.num_levels}),
      map_cloud_(std::move(map_cloud)),
      cam_from_world_initial_(world_from_cam_initial.Inverse()) {
  options_.Check();
  camera_.Check();
  // Ceres sums in thread order: one thread for bit-identical runs.
  options_.ba.num_threads = options_.deterministic    ? 1
                            : options_.ba_threads > 0 ? options_.ba_threads
                                                      : options_.num_threads;
  if (plane_map) {
    planes_ = std::make_unique<PlaneAssociator>(*plane_map, options_.planes);
    if (options_.record_plane_evidence) {
      evidence_ = std::make_unique<PlaneEvidence>(*plane_map, *planes_, options_.map_update);
    }
    // An exact start is locked from frame 0; the locker still re-registers after a loss.
    locker_ = std::make_unique<MapLocker>(*plane_map, options_.map_lock, start_prior,
                                          world_from_cam_initial);
    if (!options_.deterministic) {
      // Run reads only the locker's plane map, never the state the frame thread changes.
      registration_worker_ = std::make_unique<JobWorker<RegistrationJob>>(
          [locker = locker_.get()](RegistrationJob& job) { locker->Run(job); });
    }
  }
  if (map_cloud_ && options_.depth.window_surfaces) {
    cloud_surfaces_ = std::make_unique<CloudSurfaces>(*map_cloud_, options_.depth.surfaces);
  }
  if (!planes_ && !cloud_surfaces_) options_.ba.lambda = 1.0;  // nothing to weigh it against
  if (!options_.deterministic) {
    ba_scheduler_ = std::make_unique<BaScheduler>(
        [camera = camera_, options = options_.ba](BaJob& job) { SolveBaJob(camera, options, job); },
        options_.ba_max_lag_frames);
  }
}

Tracker::~Tracker() = default;

TrackResult Tracker::Track(const cv::Mat& left, const cv::Mat& right, double timestamp) {
  const auto start = Clock::now();
  StereoFeatures features = ExtractFeatures(left, right);
  return TrackFeatures(std::move(features), timestamp, MillisecondsSince(start));
}

StereoFeatures Tracker::ExtractFeatures(const cv::Mat& left, const cv::Mat& right) const {
  StereoFeatures features =
      ExtractStereoFeatures(left, right, camera_, extractor_, options_.stereo);
  if (map_cloud_ && options_.depth.frame_refinement) {
    features.dense = ComputeDenseDisparity(left, right, options_.depth.stereo);
  }
  return features;
}

void Tracker::RefineWithMapDepth(const DenseDisparity& disparity, Frame& frame, FrameStats& stats) {
  std::vector<PoseObservation> visual;
  for (int i = 0; i < frame.size(); ++i) {
    const int id = frame.map_point_ids[i];
    if (id < 0 || frame.outlier[i] || !map_.HasPoint(id)) continue;
    const cv::KeyPoint& kp = frame.keypoint(i);
    visual.push_back({map_.point(id).point_in_world, kp.pt.x, kp.pt.y, frame.features.u_right[i],
                      extractor_.InverseLevelSigma2(kp.octave)});
  }
  const DepthRefinement refined = RefinePoseWithMapDepth(camera_, frame.cam_from_world, visual,
                                                         *map_cloud_, disparity, options_.depth);
  stats.depth_refused = refined.refused;
  if (!refined.applied) return;
  frame.cam_from_world = refined.cam_from_world;
  stats.depth_points = refined.selection.used;
  stats.depth_residual_px = refined.median_abs_residual_px;
}

Rigid3d Tracker::PredictPose() const {
  if (!last_frame_) return cam_from_world_initial_;
  Rigid3d pose = last_frame_->cam_from_world;
  if (velocity_) {
    Rigid3d step = *velocity_;
    if (frames_skipped_ > 0) {
      // Across an outage only the heading rate persists (a car turns for seconds); pitch and roll
      // rates are suspension oscillation, and extrapolated over many frames they tilt the
      // predicted pose by degrees. The camera's y axis is the vehicle's vertical.
      const Eigen::Vector3d omega = LogSO3(step.RotationMatrix());
      step.rotation = Eigen::Quaterniond(ExpSO3(Eigen::Vector3d(0, omega.y(), 0)));
    }
    for (int k = 0; k <= frames_skipped_; ++k) pose = step * pose;
  }
  return pose;
}

TrackResult Tracker::SkipFrame(double timestamp) {
  (void)timestamp;  // the pose only depends on the frame count
  TrackResult result;
  result.stats.frame = next_frame_id_++;
  result.stats.skipped = true;
  if (planes_) result.stats.map_lock = MapLockName(map_lock());
  result.stats.state = last_frame_ ? TrackingState::kTracking : TrackingState::kLost;
  const Rigid3d pose = PredictPose();
  // The last frame stays the one with features; the next prediction steps once more.
  if (last_frame_) ++frames_skipped_;
  result.world_from_cam = pose.Inverse();
  return result;
}

TrackResult Tracker::TrackFeatures(StereoFeatures features, double timestamp, double ms_extract) {
  FrameStats stats;
  stats.frame = next_frame_id_;
  stats.ms_extract = ms_extract;
  stats.features = static_cast<int>(features.left.keypoints.size());
  stats.stereo_matches = features.num_stereo_matches();
  left_pyramid_ = features.left.pyramid;  // shallow: the Frame drops its own
  const DenseDisparity disparity = std::move(features.dense);
  Frame frame(next_frame_id_++, timestamp, std::move(features), camera_);

  const auto track_start = Clock::now();
  CatchUpWithWorkers(stats, track_start);
  const Rigid3d predicted = PredictPose();
  bool tracked = false;
  if (last_frame_) {
    const TrackingContext context{camera_, extractor_, options_};
    tracked = (velocity_ && TrackWithMotionModel(context, map_, *last_frame_, predicted, frame)) ||
              TrackWithReferenceKeyframe(context, map_, reference_keyframe_id_, *last_frame_,
                                         velocity_.has_value(), predicted, frame);
  }
  stats.ms_track = MillisecondsSince(track_start);
  if (tracked) {
    const auto local_start = Clock::now();
    stats.inliers = TrackLocalMap(TrackingContext{camera_, extractor_, options_}, map_, frame,
                                  reference_keyframe_id_);
    tracked = stats.inliers >= options_.min_tracked_inliers;
    // Hybrid mode before the map lock: the cloud's frame is not yet the trajectory's.
    const bool cloud_frame_known = !locker_ || locker_->PlanesActive();
    if (tracked && map_cloud_ && cloud_frame_known && !disparity.empty()) {
      RefineWithMapDepth(disparity, frame, stats);
    }
    stats.ms_local_map = MillisecondsSince(local_start);
  }

  if (!tracked && last_frame_ && stats.stereo_matches < options_.min_tracked_inliers) {
    // Lost on a frame too poor to restart from (blank, blinded): predict, keep the last good
    // frame as the motion model's base, and try again on the next frame.
    stats.state = TrackingState::kLost;
    lost_before_ = true;
    ++frames_skipped_;
    return {predicted.Inverse(), stats};
  }
  bool make_keyframe = false;
  if (tracked) {
    stats.state = lost_before_ ? TrackingState::kRelocalized : TrackingState::kTracking;
    lost_before_ = false;
    // Per-frame velocity, also across skipped frames (the relative motion spread evenly).
    const Rigid3d step = frame.cam_from_world * last_frame_->cam_from_world.Inverse();
    velocity_ = frames_skipped_ == 0 ? step : ExpSE3(LogSE3(step) / (frames_skipped_ + 1));
    make_keyframe = NeedKeyframe(frame, stats.inliers);
  } else {
    RestartFromStereo(frame, predicted, stats);
    make_keyframe = true;
  }
  if (make_keyframe) InsertKeyframe(frame, stats);

  // Outliers are forgotten: the next frame searches only the confirmed matches.
  for (int i = 0; i < frame.size(); ++i) {
    if (frame.outlier[i]) frame.map_point_ids[i] = -1;
    frame.outlier[i] = false;
  }
  stats.tracked_points = frame.NumTracked();
  if (!tracked) stats.inliers = 0;
  if (planes_) stats.map_lock = MapLockName(map_lock());
  last_from_reference_ =
      frame.cam_from_world * map_.keyframe(reference_keyframe_id_).cam_from_world.Inverse();
  TrackResult result;
  result.world_from_cam = frame.cam_from_world.Inverse();
  result.stats = stats;
  last_frame_ = std::move(frame);
  frames_skipped_ = 0;
  return result;
}

TrackedFrameView Tracker::DescribeLastFrame(bool with_plane_updates) const {
  TrackedFrameView view;
  if (left_pyramid_.empty()) return view;
  view.frame = next_frame_id_ - 1;
  view.left = left_pyramid_.front();
  if (planes_) view.disabled_planes = planes_->DisabledIds();
  if (with_plane_updates && evidence_) view.plane_updates = evidence_->Summarize();
  // A lost frame is not last_frame_: its keypoints were never matched.
  if (!last_frame_ || last_frame_->id != view.frame) return view;
  for (int i = 0; i < last_frame_->size(); ++i) {
    const int point_id = last_frame_->map_point_ids[i];
    if (point_id < 0) continue;
    const auto point = map_.points().find(point_id);
    if (point == map_.points().end()) continue;
    view.tracked.push_back(last_frame_->keypoint(i).pt);
    std::optional<int> plane;
    if (planes_) plane = planes_->Associate(point->second.point_in_world);
    view.tracked_plane.push_back(plane.value_or(-1));
  }
  return view;
}

void Tracker::CatchUpWithWorkers(FrameStats& stats, Clock::time_point track_start) {
  const bool ba_overdue = ba_scheduler_ && ba_scheduler_->Overdue(stats.frame);
  ApplyBaResults(stats, /*wait=*/ba_overdue);
  if (ba_overdue) stats.ms_ba += MillisecondsSince(track_start);
  ApplyLockResults(stats, nullptr, /*wait=*/false);
  SubmitDeferredBa(stats);
  if (planes_) stats.map_lock = MapLockName(map_lock());
}

void Tracker::RestartFromStereo(Frame& frame, const Rigid3d& predicted, FrameStats& stats) {
  stats.state = last_frame_ ? TrackingState::kLost : TrackingState::kTracking;
  lost_before_ = last_frame_.has_value();
  frame.cam_from_world = predicted;
  // The new map is tied to the old one only by the motion model: register it again.
  if (locker_ && last_frame_) locker_->OnLoss(predicted.Inverse(), map_.last_keyframe_id() + 1);
  std::fill(frame.map_point_ids.begin(), frame.map_point_ids.end(), -1);
  std::fill(frame.outlier.begin(), frame.outlier.end(), false);
}

bool Tracker::NeedKeyframe(const Frame& frame, int inliers) const {
  const int num_keyframes = static_cast<int>(map_.keyframes().size());
  const int min_observations = num_keyframes <= 2 ? 2 : 3;
  const int reference_matches =
      map_.HasKeyframe(reference_keyframe_id_)
          ? map_.NumTrackedPoints(reference_keyframe_id_, min_observations)
          : 0;
  int tracked_close = 0, untracked_close = 0;
  for (int i = 0; i < frame.size(); ++i) {
    const float depth = frame.features.depth[i];
    if (depth <= 0 || depth >= CloseDepth()) continue;
    if (frame.map_point_ids[i] >= 0 && !frame.outlier[i]) {
      ++tracked_close;
    } else {
      ++untracked_close;
    }
  }
  const bool need_close = tracked_close < options_.keyframe_min_close_tracked &&
                          untracked_close > options_.keyframe_min_close_untracked;
  KeyframeRuleInput input;
  input.frames_since_keyframe = frame.id - last_keyframe_frame_id_;
  input.mapping_idle = MappingIdle();
  input.inliers = inliers;
  input.reference_matches = reference_matches;
  input.need_close = need_close;
  if (map_.HasKeyframe(map_.last_keyframe_id())) {
    input.rotation_since_keyframe_deg =
        frame.cam_from_world.rotation.angularDistance(
            map_.keyframe(map_.last_keyframe_id()).cam_from_world.rotation) *
        180.0 / M_PI;
  }
  KeyframeRuleOptions rule;
  rule.min_frames = options_.keyframe_min_frames;
  rule.max_frames = static_cast<int>(std::lround(options_.fps));
  rule.tracked_ratio = options_.keyframe_tracked_ratio;
  rule.max_rotation_deg = options_.keyframe_max_rotation_deg;
  return DecideKeyframe(input, rule).insert;
}

bool Tracker::MappingIdle() const { return !ba_scheduler_ || ba_scheduler_->Idle(); }

void Tracker::InsertKeyframe(Frame& frame, FrameStats& stats) {
  const auto start = Clock::now();
  stats.keyframe = true;
  const int kf_id = map_.AddKeyframe(frame);
  stats.keyframe_id = kf_id;
  for (int i = 0; i < frame.size(); ++i) {
    const int id = frame.map_point_ids[i];
    if (id < 0 || frame.outlier[i] || !map_.HasPoint(id)) continue;
    map_.AddObservation(id, kf_id, i);
    map_.UpdatePoint(id);
  }
  const std::vector<int> created = CreateStereoPoints(map_, kf_id, camera_, options_);
  recent_point_ids_.insert(recent_point_ids_.end(), created.begin(), created.end());
  CullRecentPoints(map_, recent_point_ids_, kf_id, options_);
  map_.UpdateConnections(kf_id);
  if (options_.triangulate_with_neighbours) {
    TriangulationOptions triangulation;
    triangulation.num_neighbours = options_.triangulation_neighbours;
    const std::vector<int> triangulated =
        TriangulateWithNeighbours(map_, kf_id, camera_, triangulation);
    recent_point_ids_.insert(recent_point_ids_.end(), triangulated.begin(), triangulated.end());
    if (!triangulated.empty()) map_.UpdateConnections(kf_id);
  }
  MaintainMap(kf_id);
  // The frame now observes what the keyframe observes (new points included).
  frame.map_point_ids = map_.keyframe(kf_id).map_point_ids;
  std::fill(frame.outlier.begin(), frame.outlier.end(), false);
  reference_keyframe_id_ = kf_id;
  last_keyframe_frame_id_ = frame.id;
  stats.ms_local_map += MillisecondsSince(start);

  const auto ba_start = Clock::now();
  if (planes_ && settle_until_keyframe_id_ >= 0 && kf_id >= settle_until_keyframe_id_) {
    planes_->SetTrajectoryCovariance(Eigen::Matrix3d::Zero());
    settle_until_keyframe_id_ = -1;
  }
  // The crease check needs this keyframe's image: checked now, even if its BA waits for the
  // worker.
  if (planes_ && (!locker_ || locker_->PlanesActive())) {
    stats.crease_check =
        planes_->CheckKeyframe(kf_id, frame.cam_from_world, camera_, left_pyramid_);
  }
  ++ba_counts_.keyframes;
  if (ba_scheduler_) {
    switch (ba_scheduler_->Admit(kf_id)) {
      case BaScheduler::Admission::kSubmitNow:
        SubmitBa(kf_id, stats, &frame);
        break;
      case BaScheduler::Admission::kDeferredSuperseding:
        ++ba_counts_.superseded;
        break;
      case BaScheduler::Admission::kDeferred:
        break;
    }
  } else if (std::optional<BaJob> job = MakeBaJob(kf_id, stats, &frame)) {
    SolveBaJob(camera_, options_.ba, *job);
    const BaApplyStats applied = ApplyWindowBa(map_, job->problem, job->result, camera_);
    if (job->result.usable) {
      RecordBaStats(*job, applied, stats);
      stats.ba_keyframe = kf_id;
      ++ba_counts_.applied;
    } else {
      ++ba_counts_.unusable;
    }
    frame.cam_from_world = map_.keyframe(kf_id).cam_from_world;
    frame.map_point_ids = map_.keyframe(kf_id).map_point_ids;
  }
  stats.ms_ba += MillisecondsSince(ba_start);
  if (locker_) {
    StartRegistration(kf_id);
    ApplyLockResults(stats, &frame, /*wait=*/false);
  }
}

void Tracker::MaintainMap(int keyframe_id) {
  const MapMaintenanceOptions& maintenance = options_.maintenance;
  if (maintenance.fuse_points) {
    const std::vector<int> dropped = FuseWithNeighbours(map_, keyframe_id, camera_, maintenance);
    if (planes_) {
      for (const int id : dropped) planes_->ForgetPoint(id);
    }
  }
  // A keyframe whose BA still has to be built must exist then; the tracker's reference keyframe
  // re-anchors the last frame after every BA.
  std::set<int> keep = {keyframe_id};
  if (ba_scheduler_ && ba_scheduler_->deferred()) keep.insert(*ba_scheduler_->deferred());
  if (reference_keyframe_id_ >= 0) keep.insert(reference_keyframe_id_);
  if (maintenance.cull_keyframes) {
    ba_counts_.culled_keyframes += static_cast<int>(
        CullRedundantKeyframes(map_, keyframe_id, CloseDepth(), maintenance, keep).size());
  }
  ba_counts_.forgotten_keyframes +=
      static_cast<int>(ForgetOldKeyframes(map_, maintenance, keep).size());
}

std::optional<BaJob> Tracker::MakeBaJob(int keyframe_id, FrameStats& stats, Frame* current) {
  BaJob job;
  job.keyframe_id = keyframe_id;
  // Before the map lock the planes' frame is unknown: visual BA only.
  const bool planes_active = planes_ && (!locker_ || locker_->PlanesActive());
  TrackerOptions window_options = options_;
  if (lock_window_pending_ && planes_active) {
    // The lock left the trajectory off by the registration's error, anchors included: one
    // window over the segment, no anchor, lets the planes pull all of it at once. Its oldest
    // keyframe stays where the lock put it and holds the gauge: with that one free too, the whole
    // segment slid along the directions few planes hold (along-track); from the exact start with
    // the default prior tiny seed 5 then ended above visual odometry (docs/experiments.md,
    // session 38).
    window_options.ba_window_keyframes = options_.map_lock.structure_keyframes;
    window_options.ba_window_keyframes_turn = options_.map_lock.structure_keyframes;
    window_options.ba_max_fixed_keyframes = 0;
    window_options.ba_fix_first_keyframe = true;
    lock_window_pending_ = false;
  }
  job.problem = BuildLocalWindow(map_, keyframe_id, window_options);
  if (planes_active) {
    // The window is measured once, in the frame the BA will solve it in: records of a window the
    // consensus then moved would be the trajectory's offset, not the planes'.
    WindowPointEstimates estimates =
        EstimateWindowPoints(job.problem, map_, camera_, options_.planes);
    RecordWindow(job.problem, estimates, *planes_);
    planes_->CloseRecords();
    if (MoveMapByPlaneConsensus(stats, current)) {
      planes_->DiscardRecords();
      job.problem = BuildLocalWindow(map_, keyframe_id, options_);
      estimates = EstimateWindowPoints(job.problem, map_, camera_, options_.planes);
      RecordWindow(job.problem, estimates, *planes_);
      planes_->CloseRecords();
    }
    planes_->CommitRecords();
    planes_->UpdateHealth(AssociateWindowPlanes(job.problem, estimates, options_.planes, *planes_));
    if (evidence_) RecordEvidence(keyframe_id, job.problem, estimates);
    // Hybrid: the points on no plane of the plane map, on a flat patch of the cloud.
    if (cloud_surfaces_) cloud_surfaces_->Associate(job.problem, estimates, options_.planes);
  } else if (cloud_surfaces_ && !planes_) {
    cloud_surfaces_->Associate(job.problem,
                               EstimateWindowPoints(job.problem, map_, camera_, options_.planes),
                               options_.planes);
  }
  if (planes_) stats.planes_disabled = planes_->num_disabled();
  if (job.problem.observations.empty()) {
    ++ba_counts_.empty;  // a keyframe without points
    return std::nullopt;
  }
  job.snapshot = SnapshotWindow(map_, job.problem);
  return job;
}

void Tracker::RecordEvidence(int keyframe_id, const WindowProblem& problem,
                             const WindowPointEstimates& estimates) {
  std::vector<EvidencePoint> points;
  points.reserve(problem.points.size());
  for (std::size_t i = 0; i < problem.points.size(); ++i) {
    if (!estimates[i]) continue;
    const MapPoint& point = map_.point(problem.points[i].id);
    if (point.observations.empty()) continue;
    // Any camera that saw the point draws a ray through the space in front of it.
    const int observer = point.observations.begin()->first;
    points.push_back({problem.points[i].id, *estimates[i], map_.keyframe(observer).CameraCenter()});
  }
  const int frame = map_.keyframe(keyframe_id).frame_id;
  evidence_->ObserveWindow(frame, points);
  evidence_->NoteDisabled(frame);
}

void Tracker::SubmitBa(int keyframe_id, FrameStats& stats, Frame* current) {
  std::optional<BaJob> job = MakeBaJob(keyframe_id, stats, current);
  // MappingIdle() held: the worker accepts the job.
  if (!job) return;
  if (!ba_scheduler_->Submit(std::move(*job), stats.frame)) ++ba_counts_.superseded;
}

void Tracker::SubmitDeferredBa(FrameStats& stats) {
  if (!ba_scheduler_) return;
  const std::optional<int> deferred = ba_scheduler_->TakeDeferredWhenIdle();
  if (!deferred) return;
  const int keyframe_id = *deferred;
  if (!map_.HasKeyframe(keyframe_id)) {
    ++ba_counts_.empty;
    return;
  }
  const auto start = Clock::now();
  SubmitBa(keyframe_id, stats, nullptr);
  stats.ms_ba += MillisecondsSince(start);
}

void Tracker::ApplyBaResults(FrameStats& stats, bool wait) {
  if (!ba_scheduler_) return;
  std::optional<BaJob> job = ba_scheduler_->TakeResult(wait);
  if (!job) return;
  if (!ba_scheduler_->Current(*job)) {
    // Solved in the frame before a map-lock correction: applying it would undo the correction.
    stats.ba_discarded = true;
    ++ba_counts_.discarded;
    return;
  }
  if (!job->result.usable) {
    ++ba_counts_.unusable;
    return;
  }
  const BaApplyStats applied =
      ApplyWindowBa(map_, job->problem, job->result, camera_, &job->snapshot);
  RecordBaStats(*job, applied, stats);
  stats.ba_keyframe = job->keyframe_id;
  ++ba_counts_.applied;
  ba_counts_.stale_keyframes += applied.stale_keyframes;
  ba_counts_.stale_points += applied.stale_points;
  if (last_frame_ && map_.HasKeyframe(reference_keyframe_id_)) {
    last_frame_->cam_from_world =
        last_from_reference_ * map_.keyframe(reference_keyframe_id_).cam_from_world;
  }
}

void Tracker::Finish() {
  FrameStats ignored;
  // A lock applied now comes after every frame given (its LockEvent says so).
  ignored.frame = next_frame_id_;
  ApplyBaResults(ignored, /*wait=*/true);
  ApplyLockResults(ignored, nullptr, /*wait=*/true);
  // The last keyframe's deferred BA: solved and applied, so that every keyframe is accounted for.
  SubmitDeferredBa(ignored);
  ApplyBaResults(ignored, /*wait=*/true);
}

}  // namespace planeloc
