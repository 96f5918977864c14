#include "planeloc/tracking/odometry_options.h"

#include <algorithm>
#include <cstdint>
#include <string>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// The same prefix as the pipeline's checks: a user sees one options table (TrackerOptions).
void Require(bool condition, const std::string& what) {
  if (!condition) throw OptionsError("TrackerOptions: " + what);
}

}  // namespace

void OdometryOptions::Check() const {
  orb.Check();
  stereo.Check();
  pose.Check();
  Require(close_depth_baselines > 0, "close_depth_baselines must be > 0");
  Require(fps > 0, "fps must be > 0");
  Require(motion_search_radius > 0, "motion_search_radius must be > 0");
  Require(min_motion_matches >= 3, "min_motion_matches must be >= 3");
  Require(min_tracked_inliers >= 3, "min_tracked_inliers must be >= 3");
  Require(max_local_keyframes >= 1, "max_local_keyframes must be >= 1");
  Require(local_search_radius > 0, "local_search_radius must be > 0");
  Require(keyframe_tracked_ratio > 0 && keyframe_tracked_ratio <= 1,
          "keyframe_tracked_ratio must be in (0, 1]");
  Require(keyframe_min_frames >= 0, "keyframe_min_frames must be >= 0");
  Require(keyframe_max_rotation_deg >= 0 && keyframe_max_rotation_deg <= 180,
          "keyframe_max_rotation_deg must be in [0, 180] (0: off)");
  Require(keyframe_min_close_tracked >= 0, "keyframe_min_close_tracked must be >= 0");
  Require(keyframe_min_close_untracked >= 0, "keyframe_min_close_untracked must be >= 0");
  Require(min_new_stereo_points >= 0, "min_new_stereo_points must be >= 0");
  Require(far_depth_baselines >= close_depth_baselines,
          "far_depth_baselines must be >= close_depth_baselines");
  Require(triangulation_neighbours >= 1, "triangulation_neighbours must be >= 1");
  Require(ba_window_keyframes >= 1, "ba_window_keyframes must be >= 1");
  Require(ba_max_fixed_keyframes >= 0, "ba_max_fixed_keyframes must be >= 0");
  Require(ba_window_keyframes_turn >= ba_window_keyframes,
          "ba_window_keyframes_turn must be >= ba_window_keyframes");
  Require(ba_turn_angle_deg > 0.0, "ba_turn_angle_deg must be > 0");
  Require(min_found_ratio >= 0 && min_found_ratio <= 1, "min_found_ratio must be in [0, 1]");
  Require(min_point_observations >= 1, "min_point_observations must be >= 1");
  maintenance.Check();
  // Forgetting must not reach into the keyframes that tracking and the BA still use. The sum in
  // 64 bits: both window sizes may be INT_MAX in a settings file (fuzzing finding, session 35).
  const std::int64_t ba_reach =
      static_cast<std::int64_t>(ba_window_keyframes_turn) + ba_max_fixed_keyframes;
  Require(maintenance.keep_keyframes == 0 ||
              maintenance.keep_keyframes >= std::max<std::int64_t>(max_local_keyframes, ba_reach),
          "maintenance.keep_keyframes must be 0 or >= max(max_local_keyframes, "
          "ba_window_keyframes_turn + ba_max_fixed_keyframes)");
}

}  // namespace planeloc
