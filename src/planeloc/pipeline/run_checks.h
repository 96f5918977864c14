// Checks over the first frames of `planeloc run` that catch an input which would otherwise give a
// plausible-looking wrong answer: a wrong stereo baseline (an error) and a depth prior's map cloud
// that does not cover the drive (a warning).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <utility>

#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/stereo_source.h"
#include "planeloc/pipeline/frame_stats.h"

namespace planeloc {

// A wrong stereo baseline scales the whole trajectory: bf x 100 turns a car at 10 m/s into one
// at 1 km/s, with nothing else looking wrong. Over the first half second of camera time the speed
// is checked against what any vehicle or handheld rig can do.
class CalibrationSpeedCheck {
 public:
  // `calibration`: the file named in the error.
  explicit CalibrationSpeedCheck(std::string calibration) : calibration_(std::move(calibration)) {}

  // Frame i's pose, in order. Throws InputError naming the calibration once the first half second
  // (at least 5 frames) moved faster than 100 m/s; the frames written so far stay written.
  void Add(const StereoSource& sequence, std::size_t i, const Rigid3d& world_from_cam);

 private:
  static constexpr double kWindowSeconds = 0.5;
  static constexpr std::size_t kMinFrames = 5;
  static constexpr double kMaxSpeed = 100.0;     // m/s, 360 km/h
  static constexpr double kTypicalSpeed = 10.0;  // m/s, for the factor in the message
  std::string calibration_;
  Eigen::Vector3d first_position_ = Eigen::Vector3d::Zero();
  bool done_ = false;
};

// The depth prior's map cloud must lie around the drive, in the frame of the initial pose. Over
// the first tracked frames, a cloud that refined fewer than half of them is named in a warning
// with the likely causes; the run goes on (as visual odometry where the cloud has nothing).
class MapCloudCoverageCheck {
 public:
  // `by_windows`: the frames are not refined (DepthPrior.frameRefinement off), so the evidence is
  // the window BAs applied in those frames that had patch residuals.
  MapCloudCoverageCheck(std::string path, bool by_windows)
      : path_(std::move(path)), by_windows_(by_windows) {}

  void Add(const FrameStats& stats);

  // Whether the warning was logged (after kFrames tracked frames).
  bool warned() const { return warned_; }

  static constexpr int kFrames = 20;

 private:
  std::string path_;
  bool by_windows_;
  int tracked_ = 0, windows_ = 0, used_ = 0;
  bool done_ = false;
  bool warned_ = false;
};

}  // namespace planeloc
