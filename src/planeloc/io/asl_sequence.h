// Lazy reader of a stereo sequence in the ASL / EuRoC MAV layout (issue 35):
//   mav0/cam0/data.csv        "#timestamp [ns],filename", one image per line
//   mav0/cam0/data/<filename> the left image (raw: distorted, not rectified)
//   mav0/cam0/sensor.yaml     T_BS (body_from_sensor, 4x4 row-major), resolution, pinhole
//                             intrinsics [fu, fv, cu, cv], radial-tangential distortion
//   mav0/cam1/...             the right camera, the same
// The raw pairs are rectified on load (io/stereo_rectifier.h, from the extrinsics the two T_BS
// give, as ORB-SLAM3 does for EuRoC). Frames are the cam0 timestamps that cam1 has too.
// Errors are planeloc::InputError naming the file (and line) and the fix.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/stereo_rectifier.h"
#include "planeloc/io/stereo_source.h"

namespace planeloc {

class AslSequence : public StereoSource {
 public:
  // True when `folder` is an ASL `mav0` folder (it holds cam0/data.csv) or holds one.
  static bool IsAslFolder(const std::filesystem::path& folder);
  // Reads both cameras' sensor.yaml and data.csv; decodes no image.
  static AslSequence Open(const std::filesystem::path& folder);

  std::string name() const override { return mav0_.string(); }
  std::string calibration_name() const override {
    return (mav0_ / "cam0" / "sensor.yaml").string();
  }
  std::size_t size() const override { return timestamps_ns_.size(); }
  // The rectified stereo camera (the raw images' size).
  const StereoCamera& camera() const override { return rectifier_->camera(); }
  // Seconds on the dataset's clock (Unix time for EuRoC), so that a TUM trajectory written from
  // it pairs with the ground truth's csv (`eval --format euroc`, evo_ape euroc).
  double timestamp(std::size_t index) const override;
  // The dataset's clock: nanoseconds, as in data.csv and the ground truth's csv.
  std::int64_t timestamp_ns(std::size_t index) const { return timestamps_ns_.at(index); }
  StereoPair LoadStereoPair(std::size_t index) const override;
  bool HasFrame(std::size_t index) const override;
  std::string MissingFrame(std::size_t index) const override;

  const std::filesystem::path& mav0() const { return mav0_; }
  // The rectified left camera in the body (IMU) frame: T_BS of cam0 followed by the
  // rectification's rotation, so that body poses (the ground truth) map to camera poses.
  const Rigid3d& body_from_camera() const { return body_from_camera_; }
  // cam0 frames without a cam1 image of the same timestamp (left out).
  std::size_t unpaired_frames() const { return unpaired_; }
  // world_from_camera of frame `index` (the rectified left camera) from a ground-truth csv of the
  // body (ReadEurocTrajectory): the body pose interpolated at the frame's time (linear position,
  // slerp), then body_from_camera(). Throws InputError naming the csv when the frame's time lies
  // more than 10 ms outside the ground truth's span.
  Rigid3d CameraPoseFromGroundTruth(const std::filesystem::path& csv, std::size_t index) const;

 private:
  AslSequence() = default;

  std::filesystem::path mav0_;
  std::vector<std::int64_t> timestamps_ns_;
  std::vector<std::filesystem::path> left_images_, right_images_;
  std::shared_ptr<const StereoRectifier> rectifier_;
  Rigid3d body_from_camera_;
  std::size_t unpaired_ = 0;
};

}  // namespace planeloc
