#include "planeloc/pipeline/run_checks.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "planeloc/util/error.h"

namespace planeloc {

void CalibrationSpeedCheck::Add(const StereoSource& sequence, std::size_t i,
                                const Rigid3d& world_from_cam) {
  if (done_) return;
  if (i == 0) {
    first_position_ = world_from_cam.translation;
    return;
  }
  const double seconds = sequence.timestamp(i) - sequence.timestamp(0);
  if (seconds < kWindowSeconds || i < kMinFrames) return;
  done_ = true;
  const double speed = (world_from_cam.translation - first_position_).norm() / seconds;
  if (speed <= kMaxSpeed) return;
  throw InputError(
      calibration_, 0,
      fmt::format("the stereo calibration makes the camera move at {:.0f} m/s over the first "
                  "{:.1f} s (frames 0-{}; at most {:.0f} m/s is plausible): its baseline "
                  "(bf = fx x baseline in metres) is wrong, about {:.0f}x too large for a "
                  "camera at 10 m/s",
                  speed, seconds, i, kMaxSpeed, speed / kTypicalSpeed),
      "correct the baseline (the settings' Camera.bf, or the right camera's projection P1 / "
      "P_rect_01 in calib.txt); with --calib-from-settings, try without it");
}

void MapCloudCoverageCheck::Add(const FrameStats& stats) {
  if (done_ || stats.skipped || stats.state == TrackingState::kLost || stats.frame == 0) return;
  ++tracked_;
  if (by_windows_) {
    windows_ += stats.ba_keyframe.has_value() ? 1 : 0;
    used_ += stats.ba_keyframe && stats.ba_plane_residuals.value_or(0) > 0 ? 1 : 0;
  } else {
    used_ += stats.depth_points.has_value() ? 1 : 0;
  }
  if (tracked_ < kFrames) return;
  done_ = true;
  const int total = by_windows_ ? windows_ : tracked_;
  if (total == 0 || 2 * used_ >= total) return;
  warned_ = true;
  spdlog::warn(
      "{}: the map cloud was used in only {} of the first {} {}: it has too few points in "
      "view near the stereo's. Likely causes: the cloud does not cover the drive, or is in "
      "another frame than the initial pose (--init-pose / --init-pose-from), or the stereo sees "
      "mostly what the map lacks. Those frames keep their visual-odometry pose ({} in --stats).",
      path_, used_, total, by_windows_ ? "local BA windows" : "tracked frames",
      by_windows_ ? "ba_plane_residuals" : "depth_points");
}

}  // namespace planeloc
