// Tracks a whole sequence (a KITTI-layout folder or any StereoSource, e.g. a rosbag): reads frames
// one at a time, writes one pose per frame (flushed), optional per-frame JSON stats, and the
// effective settings next to the trajectory.
// The controller behind `planeloc run`; it does no maths itself.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/initial_pose.h"
#include "planeloc/io/kitti_sequence.h"
#include "planeloc/io/stereo_source.h"
#include "planeloc/io/trajectory.h"
#include "planeloc/pipeline/run_observer.h"
#include "planeloc/pipeline/settings.h"
#include "planeloc/pipeline/tracker.h"

namespace planeloc {

struct RunOptions {
  std::filesystem::path sequence;  // KITTI odometry sequence folder or raw drive folder
  CameraChoice cameras = CameraChoice::kAuto;
  // Frames from this source (e.g. a rosbag, ros/bag_sequence.h) instead of `sequence`.
  std::shared_ptr<const StereoSource> source;
  Rigid3d world_from_cam_initial;         // pose of frame 0; the trajectory is in its frame
  std::filesystem::path trajectory_path;  // required
  TrajectoryFormat format = TrajectoryFormat::kKitti;
  std::optional<std::filesystem::path> stats_path;  // JSON lines, one per frame
  // Written at the end, in `format`: every frame in the map frame as the run knows it then, the
  // frames tracked before the map lock re-expressed by the lock's correction
  // (pipeline/final_trajectory.h). trajectory_path keeps each frame as it was tracked.
  std::optional<std::filesystem::path> final_trajectory_path;
  // One JSON object with the end-of-run summary (RunSummary::ToJson); `planeloc run --stats X`
  // writes it to X.summary.json.
  std::optional<std::filesystem::path> summary_path;
  // ORB-SLAM2 / ORB-SLAM3 settings file and/or planeloc keys (OpenCV FileStorage YAML).
  std::optional<std::filesystem::path> settings_path;
  // Track with the settings file's intrinsics and baseline instead of the sequence's calibration
  // (also chosen by the file's System.calibrationFromSettings: 1). Needs settings_path.
  bool calibration_from_settings = false;
  // planes.json of `planeloc map planes`, in the frame of world_from_cam_initial; none: visual
  // odometry only (the baseline).
  std::optional<std::filesystem::path> planes_path;
  // The LiDAR map cloud (.pcd/.ply/.xyz) in the frame of world_from_cam_initial: with it each
  // frame's pose is refined by the depth-to-map residual (`--prior depth`, prior/depth_prior.h),
  // from world_from_cam_initial as given (no map lock).
  std::optional<std::filesystem::path> map_cloud_path;
  // How well world_from_cam_initial is known in the plane map's frame (--init-sigma); exact by
  // default. Unless exact, the run registers itself to the plane map (prior/map_lock.h).
  StartPrior start_prior;
  // What the run learned about each plane of planes_path (io/map_updates.h), written at the end
  // (`planeloc run --map-update`; needs planes_path).
  std::optional<std::filesystem::path> map_update_path;
  bool write_effective_settings = true;  // <trajectory>.config.yaml
  // The folder `planeloc report` reads (eval/html_report.h lists its files), written after the
  // run: copies of the trajectory, stats, summary, effective settings and plane map, run.json,
  // and overlays of up to report_keyframe_images keyframes (pipeline/keyframe_overlay.h).
  std::optional<std::filesystem::path> report_dir;
  int report_keyframe_images = 4;
  bool deterministic = false;
  // Replay at the camera's rate: frame i arrives (and only then is decoded) at its times.txt time
  // after the first frame's, as from a live camera; nothing is dropped. Each frame's latency,
  // arrival to pose, goes into its stats and the summary. The frame thread never waits for the
  // local BA (LocalBA.maxLagFrames 0).
  bool realtime = false;
  int threads = 0;     // 0: keep the settings' value
  int max_frames = 0;  // 0: all
  bool show_progress = true;
  // Called on the tracking thread at the start, after every frame and at the end (the live view).
  std::shared_ptr<RunObserver> observer;
};

struct RunSummary {
  int frames = 0;
  int tracked = 0;  // state tracking or relocalized
  int lost = 0;
  int skipped = 0;
  int keyframes = 0;
  double mean_tracked_points = 0;
  double median_ba_reprojection_px = 0;  // median over the BA medians reported
  int planes = 0;                        // planes in the plane map (0: visual only)
  double mean_ba_plane_residuals = 0;    // point-to-plane residuals a local BA, on average
  int planes_disabled = 0;               // planes disabled during the run (biased, see tracking)
  // Depth prior: points of the voxelized map cloud, frames whose pose the depth residual refined
  // and the map points used per refined frame, on average.
  std::size_t map_cloud_points = 0;
  int depth_frames = 0;
  int depth_refused = 0;  // frames whose refinement went beyond DepthPrior.maxCorrection
  double mean_depth_points = 0;
  int consensus_corrections = 0;  // map moves by the planes' consensus (trajectoryConsensus)
  double seconds = 0;             // wall time of the tracking loop
  // Real-time replay only: frame latency (arrival to pose) percentiles, milliseconds.
  std::optional<double> latency_p50_ms, latency_p99_ms, latency_max_ms;
  BaCounts ba;                          // what became of every keyframe's local BA
  std::vector<FrameStats> stats;        // per frame
  std::vector<Rigid3d> world_from_cam;  // per frame, as written
  std::vector<LockEvent> lock_events;   // map-frame corrections, in order
  std::string final_map_lock;           // "" without a plane map
  // Registration attempts before the lock, and the reasons of those that changed nothing with
  // their counts, most frequent first (Tracker::lock_refusals).
  int lock_attempts = 0;
  std::vector<std::pair<std::string, int>> lock_refusals;
  TrackerOptions options;  // effective
  StereoCamera camera;     // effective (sequence or settings calibration)
  // The LSD crease check (crease_check.h) over the checked keyframes: their number, the mean
  // visible and confirmed creases and the median of their median edge distances (px).
  int crease_keyframes = 0;
  double mean_visible_creases = 0, mean_confirmed_creases = 0;
  std::optional<double> median_edge_px;
  // With map_update_path: planes per status (unseen, confirmed, corrected, contradicted).
  std::map<std::string, int> map_update_counts;
  // The counts above (not the per-frame vectors) as one JSON object.
  std::string ToJson() const;
};

// Throws InputError for unreadable input (sequence, settings, output folder).
RunSummary RunSequence(const RunOptions& options);

// "S_XY S_Z S_YAW_DEG" of --init-sigma; throws InputError naming the option.
StartPrior ParseInitSigma(const std::string& text);

}  // namespace planeloc
