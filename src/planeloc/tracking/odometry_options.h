// Options of the stereo visual odometry: feature extraction, stereo matching, pose optimisation,
// the keyframe rule, map points and the local BA window. They know nothing of a prior map; the
// pipeline's TrackerOptions (pipeline/settings.h) adds the plane map, the map lock and threading,
// and reads all of them from a settings file (docs/tracking.md lists the keys).
#pragma once

#include "planeloc/features/orb_extractor.h"
#include "planeloc/features/stereo_matcher.h"
#include "planeloc/optim/pose_optimizer.h"
#include "planeloc/tracking/map_maintenance.h"

namespace planeloc {

struct OdometryOptions {
  OrbOptions orb;
  StereoMatchOptions stereo;
  PoseOptimizerOptions pose;

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
  double keyframe_max_rotation_deg = 0;   // > 0: a keyframe once the view turned this far (rooms)
  int keyframe_min_close_tracked = 100;   // fewer tracked close points than this ...
  int keyframe_min_close_untracked = 70;  // ... while this many close points are unmatched

  // New map points at a keyframe: every close stereo point, and at least this many in total
  // (nearest first, also far ones), as ORB-SLAM2.
  int min_new_stereo_points = 100;
  // Far stereo points (beyond close depth but below far_depth_baselines * baseline) are also
  // turned into points when they are unmatched: they constrain rotation.
  double far_depth_baselines = 80.0;

  // New map points by triangulating the new keyframe's unmatched keypoints against its best
  // `triangulation_neighbours` covisible keyframes (ORB-SLAM2 CreateNewMapPoints;
  // Mapping.triangulateWithNeighbours). Off by default: more points and a lower ATE for fewer fps,
  // a user's trade-off (docs/tracking.md).
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

  // Map point culling: a recent point is removed when found / visible < this ratio, or when
  // it has fewer than min_point_observations observers two keyframes after its creation.
  double min_found_ratio = 0.25;
  int min_point_observations = 2;  // ORB-SLAM2 stereo: <= 3 with stereo counting 2
  // Keyframe culling, point fusion and forgetting keyframes far behind: bounded memory on long
  // drives (map_maintenance.h; Mapping.cullKeyframes, Mapping.fusePoints, Mapping.keepKeyframes).
  MapMaintenanceOptions maintenance;

  // Throws OptionsError naming the field.
  void Check() const;
};

}  // namespace planeloc
