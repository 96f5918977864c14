// Options of the stereo tracker and their settings file.
//
// A settings file is OpenCV FileStorage YAML, as ORB-SLAM2 and ORB-SLAM3 read it (`%YAML:1.0`
// header, `key:value`, quoted strings, `!!opencv-matrix`): either ORB-SLAM layout (see
// settings_camera.h for the camera keys) and planeloc's own keys (`Tracking.*`, `LocalBA.*`,
// `Stereo.*`, `Planes.*`, ...). Every key is optional: built-in defaults apply. Keys that do not
// apply to planeloc (viewer, IMU, distortion of rectified images, ...) are listed as ignored;
// unknown keys are warnings; mistyped or invalid values are one InputError naming the file, the
// line, the key, the value and the expected form. The full key list is in docs/tracking.md.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/features/orb_extractor.h"
#include "planeloc/features/stereo_matcher.h"
#include "planeloc/geometry/camera.h"
#include "planeloc/optim/pose_optimizer.h"
#include "planeloc/optim/window_ba.h"
#include "planeloc/tracking/map_lock.h"
#include "planeloc/tracking/map_maintenance.h"
#include "planeloc/tracking/plane_association.h"
#include "planeloc/tracking/settings_camera.h"

namespace planeloc {

struct TrackerOptions {
  OrbOptions orb;
  StereoMatchOptions stereo;
  PoseOptimizerOptions pose;
  WindowBaOptions ba = [] {
    WindowBaOptions o;
    o.lambda = 0.5;  // used only with a plane map, see `planes` below
    return o;
  }();

  // Stereo points closer than close_depth_baselines * baseline are "close" (ORB-SLAM2 ThDepth):
  // reliable depth, used to create map points and to decide keyframes.
  double close_depth_baselines = 40.0;
  // Frame rate of the sequence (Hz): after `fps` frames without a keyframe, a frame that meets
  // the tracked-ratio condition becomes one even while the local BA is busy (ORB-SLAM2 mMaxFrames;
  // see keyframe_rule.h).
  double fps = 10.0;

  // Frame-to-frame search radius at level 0 (pixels), scaled by the pyramid scale of the level;
  // doubled once if too few matches are found.
  double motion_search_radius = 7.0;
  // Minimum frame-to-frame matches before falling back to the reference keyframe.
  int min_motion_matches = 20;
  // Pose-optimization inliers after the local-map search below which the frame is lost.
  int min_tracked_inliers = 30;
  // Local map: keyframes sharing points with the frame plus their covisible neighbours.
  int max_local_keyframes = 60;
  // Multiplier of the local-map search radius (ORB-SLAM2 th: 1 for stereo).
  double local_search_radius = 1.0;

  // Keyframe decision (ORB-SLAM2 stereo rules, keyframe_rule.h).
  double keyframe_tracked_ratio = 0.75;   // tracked points vs the reference keyframe's
  int keyframe_min_frames = 0;            // frames after a keyframe before an idle mapper takes one
  int keyframe_min_close_tracked = 100;   // fewer tracked close points than this ...
  int keyframe_min_close_untracked = 70;  // ... while this many close points are unmatched

  // New map points at a keyframe: every close stereo point, and at least this many in total
  // (nearest first, also far ones), as ORB-SLAM2.
  int min_new_stereo_points = 100;
  // Far stereo points (beyond close depth but below far_depth_baselines * baseline) are also
  // turned into points when they are unmatched: they constrain rotation.
  double far_depth_baselines = 80.0;

  // New map points by triangulating the new keyframe's unmatched keypoints against its best
  // `triangulation_neighbours` covisible keyframes (ORB-SLAM2 CreateNewMapPoints). Off by
  // default: +50 % tracked points and a lower sim ATE, but 30 % fewer fps on real KITTI frames
  // (the extra points cost local-map tracking and BA time; see docs/tracking.md).
  bool triangulate_with_neighbours = false;
  int triangulation_neighbours = 10;

  // Local BA window: the new keyframe and its best covisible keyframes (free), plus up to
  // max_fixed_keyframes other observers of the window's points (fixed anchors).
  int ba_window_keyframes = 10;
  int ba_max_fixed_keyframes = 20;
  // The window grows to ba_window_keyframes_turn while the heading changed by more than
  // ba_turn_angle_deg over the last ba_window_keyframes keyframes: at a street corner, where
  // tracking is weakest, the paper's sliding window "reaches the maximum value".
  int ba_window_keyframes_turn = 20;
  double ba_turn_angle_deg = 15.0;
  // The first keyframe of the map anchors the gauge (the given initial pose). After a full map
  // lock the plane map holds all six DoF, and the tracker's first window after it frees it.
  bool ba_fix_first_keyframe = true;
  // Threaded mode: a BA still running this many frames after it was submitted is waited for at
  // the start of the frame (0 = no bound). When frames come faster than the BA solves (an offline
  // run, the next frame's features extracted in parallel) the results otherwise land later and
  // later, and the frames in between track against the unadjusted map: kitti07-like seed 1, ATE
  // 0.096-0.138 m unbounded vs 0.064-0.077 m with 3 (deterministic 0.075 m), same fps. With 1 a
  // BA always lands at the frame after its keyframe, so the run no longer depends on timing: on
  // kitti07-like seeds 1, 2 and 3 (2 runs each) 1 gave 0.077 / 0.109 / 0.060 m, every run the
  // same, against deterministic 0.075 / 0.107 / 0.058 m, and 3 gave 0.066-0.072 / 0.070-0.162 /
  // 0.075-0.084 m, at 3 % more fps (44.0 vs 43.0 on seeds 1-2; docs/bench-tracking.md). At 10 Hz
  // in real time a BA lands within a frame or two and the bound never waits.
  int ba_max_lag_frames = 1;

  // With a plane map (`planeloc run --planes`): which map points lie on a LiDAR plane. The BA then
  // weighs reprojection by ba.lambda and point-to-plane by 1 - ba.lambda (LocalBA.lambda, default
  // 0.5 = both whitened terms weighted equally); without a plane map the BA is visual (lambda 1).
  PlaneAssociationOptions planes;
  // With a plane map and an uncertain start (--init-sigma): when and how the run registers its
  // structure to the plane map (tracking/map_lock.h).
  MapLockOptions map_lock;
  // Map point culling: a recent point is removed when found / visible < this ratio, or when
  // it has fewer than min_point_observations observers two keyframes after its creation.
  double min_found_ratio = 0.25;
  int min_point_observations = 2;  // ORB-SLAM2 stereo: <= 3 with stereo counting 2
  // Keyframe culling, point fusion and forgetting keyframes far behind: bounded memory on long
  // drives (map_maintenance.h; Mapping.cullKeyframes, Mapping.fusePoints, Mapping.keepKeyframes).
  MapMaintenanceOptions maintenance;

  // Deterministic: local BA in line on the tracking thread (bit-identical runs).
  bool deterministic = false;
  int num_threads = 2;  // threads for feature extraction (>= 1)
  // Ceres threads of the threaded local BA (LocalBA.threads); 0: num_threads. The tracker sets
  // ba.num_threads from this (one with `deterministic`). One by default:
  // the BA worker is already a thread beside the frame thread and the extraction, and a second
  // Ceres thread on 2 cores only oversubscribes them (kitti07-like seed 1, 5 alternated runs: 44.7
  // against 42.9 fps, ATE 0.085 against 0.091 m; docs/bench-tracking.md). `--deterministic` solves
  // with one whatever this says.
  int ba_threads = 1;

  // Throws OptionsError naming the field.
  void Check() const;
};

struct SettingsFile {
  TrackerOptions options;
  // The stereo calibration in the file (either layout), if any; see ChooseCamera.
  std::optional<SettingsCamera> camera;
  // System.calibrationFromSettings: use `camera` instead of the sequence's calibration.
  bool calibration_from_settings = false;
  std::vector<std::string> ignored;   // keys accepted but not applicable, each once, file order
  std::vector<std::string> warnings;  // unknown keys (with line), camera mismatches, ...
};

// Reads a settings file on top of `defaults`. Throws InputError (file, line, key, value and
// expected form) listing every mistyped or invalid key together, and for input planeloc cannot
// track (unrectified or fisheye stereo, see settings_camera.h). When `camera` (the sequence's
// calibration) is given, the file's calibration is compared with it (warnings only).
SettingsFile LoadTrackerSettings(const std::filesystem::path& path, const TrackerOptions& defaults,
                                 const std::optional<StereoCamera>& camera = std::nullopt);

// The effective configuration as a settings file that LoadTrackerSettings (and cv::FileStorage)
// reads back to the same values: ORB-SLAM3 v1.0 layout for the camera (Camera.type "Rectified",
// Camera1.*, Stereo.b, Camera.width/height), every planeloc key, and
// System.calibrationFromSettings. With a `rectifier` (raw images rectified on load) the camera is
// written in ORB-SLAM2's layout with LEFT/RIGHT K, D, R, P instead, so that a run with the
// written file rectifies the same way.
std::string TrackerSettingsYaml(const TrackerOptions& options, const StereoCamera& camera,
                                bool calibration_from_settings = false,
                                const StereoRectifier* rectifier = nullptr);
void WriteTrackerSettings(const std::filesystem::path& path, const TrackerOptions& options,
                          const StereoCamera& camera, bool calibration_from_settings = false,
                          const StereoRectifier* rectifier = nullptr);

}  // namespace planeloc
