// What the tracker reports: per frame (the `--stats` JSON lines), per map-frame correction, and
// what became of each keyframe's local BA. Plain data, readable without the tracker's headers.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "planeloc/geometry/rigid3.h"
#include "planeloc/prior/crease_check.h"
#include "planeloc/prior/map_registration.h"

namespace planeloc {

enum class TrackingState {
  kTracking,     // tracked against the map
  kLost,         // not tracked: pose from the motion model, map re-initialized from stereo
  kRelocalized,  // first tracked frame after a loss (against the re-initialized map)
};
const char* TrackingStateName(TrackingState state);

struct FrameStats {
  int frame = 0;
  TrackingState state = TrackingState::kTracking;
  bool skipped = false;  // images missing: motion-model pose only
  int features = 0;
  int stereo_matches = 0;
  int tracked_points = 0;  // map points matched in the frame (inliers of the final optimization)
  int inliers = 0;         // inliers of the final pose optimization
  bool keyframe = false;
  std::optional<int> keyframe_id;  // the keyframe this frame became (ba_keyframe refers to it)
  double ms_extract = 0, ms_track = 0, ms_local_map = 0, ms_ba = 0;
  // Real-time replay (RunOptions::realtime): from the frame's arrival at its camera time to its
  // pose written, milliseconds.
  std::optional<double> latency_ms;
  // Median stereo reprojection error (pixels) after the last applied local BA, when one was
  // applied during this frame.
  std::optional<double> ba_median_reprojection_px;
  // Of that BA: point-to-plane residuals (plane mode) and free keyframes of its window.
  std::optional<int> ba_plane_residuals;
  std::optional<int> ba_window_keyframes;
  // Its fixed keyframes: the anchors outside the window that see its points, or the one keyframe
  // that holds the gauge (the lock window after a map lock has no anchor).
  std::optional<int> ba_fixed_keyframes;
  // A BA result dropped because the map moved to the map frame while it ran.
  bool ba_discarded = false;
  // Keyframe whose local BA result was applied during this frame.
  std::optional<int> ba_keyframe;
  // With a plane map: the map lock after this frame (searching | partial | locked), and the
  // registration attempt that finished during this frame, as JSON.
  std::string map_lock;
  std::optional<std::string> registration;
  // Plane mode, keyframes: planes of the map disabled so far (their points sit off them).
  std::optional<int> planes_disabled;
  // Plane mode: the map moved by this (metres, map frame) because the planes agreed that the
  // trajectory sat off them (Planes.trajectoryConsensus).
  std::optional<Eigen::Vector3d> consensus_correction;
  // Depth prior: map points whose depth residual refined the pose, and their median |residual|
  // at the refined pose (level-0 pixels of disparity); absent when the frame kept its visual pose.
  std::optional<int> depth_points;
  std::optional<double> depth_residual_px;
  // The depth prior's refinement moved the pose beyond DepthPrior.maxCorrection: refused, the
  // frame kept its visual pose.
  bool depth_refused = false;
  // Plane mode, keyframes after the map lock: the LSD check of the map's creases (crease_check.h).
  std::optional<CreaseCheckStats> crease_check;
  // One JSON object on one line (the --stats format).
  std::string ToJson() const;
};

// A correction of the map frame applied during the run.
struct LockEvent {
  int frame = 0;
  MapLock lock = MapLock::kSearching;
  Rigid3d map_from_world;  // applied to the keyframes and points of the segment
  int first_keyframe_id = 0;
  bool recorrection = false;  // a re-registration while locked, not the lock itself
};

// What became of the local BA of every keyframe (end-of-run stats). After Tracker::Finish,
// keyframes = applied + superseded + discarded + unusable + empty.
struct BaCounts {
  int keyframes = 0;   // keyframes inserted: each asks for a local BA
  int applied = 0;     // solved and written back
  int superseded = 0;  // not solved: a newer keyframe's BA was requested while the worker was busy
  int discarded = 0;   // solved, then dropped: the map moved to the map frame meanwhile
  int unusable = 0;    // the solver failed; the map kept as it was
  int empty = 0;       // nothing to adjust (a window without observations)
  // Of the applied results: keyframes and points left as they were because they had been moved
  // since the window was built (a late result never undoes a newer change).
  int stale_keyframes = 0;
  int stale_points = 0;
  // Map maintenance (map_maintenance.h): keyframes erased as redundant, and as too old.
  int culled_keyframes = 0;
  int forgotten_keyframes = 0;
  std::string ToJson() const;
};

}  // namespace planeloc
