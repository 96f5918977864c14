// Lazy reader of a rectified stereo sequence in KITTI layout: the odometry layout
// (`sequences/XX/{image_0,image_1}`, `calib.txt`, `times.txt`, `velodyne/`, and optional
// `poses/XX.txt` two levels up) or the raw layout (`YYYY_MM_DD_drive_NNNN_sync/image_0X/data`,
// `calib_cam_to_cam.txt` one level up or beside, `calib_velo_to_cam.txt`, `oxts/data`).
//
// Images are read one frame at a time (a 4 500-frame sequence never sits in memory). All
// errors are planeloc::InputError naming the file, line and fix.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/stereo_source.h"

namespace planeloc {

class KittiCalibFile;

enum class CameraChoice {
  kAuto,   // grey pair if present, else colour pair
  kGrey,   // image_0/1 (odometry) or image_00/01 (raw)
  kColor,  // image_2/3 (odometry) or image_02/03 (raw), converted to grey
};
// "auto" | "grey" | "gray" | "color" | "colour"; throws InputError otherwise.
CameraChoice ParseCameraChoice(const std::string& name);

enum class KittiLayout { kOdometry, kRaw };

class KittiSequence : public StereoSource {
 public:
  // Detects the layout from the folder's contents. Reads calibration, timestamps (strictly
  // increasing) and the list of frames; decodes no image. Frame 0 must have both images, of the
  // same size (read from the PNG headers).
  static KittiSequence Open(const std::filesystem::path& folder,
                            CameraChoice cameras = CameraChoice::kAuto);

  KittiLayout layout() const { return layout_; }
  const std::filesystem::path& folder() const { return folder_; }
  std::string name() const override { return folder_.string(); }
  std::string calibration_name() const override { return camera_calibration_path_.string(); }
  std::size_t size() const override { return timestamps_.size(); }
  // Rectified stereo camera of the chosen pair, image size taken from the first left image.
  const StereoCamera& camera() const override { return camera_; }
  // Seconds from the first frame (odometry: times.txt; raw: the date-time strings).
  double timestamp(std::size_t index) const override { return timestamps_.at(index); }
  const std::vector<double>& timestamps() const { return timestamps_; }
  std::filesystem::path left_image_path(std::size_t index) const;
  std::filesystem::path right_image_path(std::size_t index) const;
  // Decodes frame `index`. Throws InputError if a file is missing, does not decode or is blank
  // (one grey value), or if left and right sizes differ from each other or from camera().
  StereoPair LoadStereoPair(std::size_t index) const override;
  // True when both image files of frame `index` exist (for skipping missing frames mid-sequence).
  bool HasFrame(std::size_t index) const override;
  // The image file of frame `index` that is missing ("" when both exist).
  std::string MissingFrame(std::size_t index) const override;

  // cam_from_velo: LiDAR (Velodyne) to the chosen left rectified camera frame, when calibrated
  // (odometry: `Tr` of calib.txt; raw: calib_velo_to_cam.txt with R_rect_00 and the camera offset).
  // The colour pair adds its x offset P2(0,3)/fx to cam0 (see docs/io.md).
  const std::optional<Rigid3d>& cam_from_velo() const { return cam_from_velo_; }
  // cam_from_velo, or an InputError naming the calibration file that lacks it (calib.txt's `Tr`
  // line; the raw layout's calib_velo_to_cam.txt) and how to add it.
  const Rigid3d& RequireCamFromVelo() const;
  // Velodyne scan file of frame `index`, if the sequence has one.
  std::optional<std::filesystem::path> velodyne_path(std::size_t index) const;

  // Ground-truth world_from_cam of the chosen left camera, first pose identity, when available
  // (odometry: ../../poses/XX.txt; raw: OXTS packets through the KITTI devkit's Mercator
  // projection and the IMU->velo->cam calibration).
  const std::optional<std::vector<Rigid3d>>& ground_truth() const { return ground_truth_; }

 private:
  void OpenOdometry(CameraChoice cameras);
  void OpenRaw(CameraChoice cameras);
  // True for the colour pair; throws InputError when the requested pair is absent.
  bool ChooseColour(CameraChoice cameras, const std::filesystem::path& grey_left,
                    const std::filesystem::path& colour_left) const;
  // Fills the image lists; left and right must hold the same file names.
  void ListFrames(const std::filesystem::path& left_dir, const std::filesystem::path& right_dir);
  void SetCameraFromCalib(const KittiCalibFile& calib, const std::string& left_key,
                          const std::string& right_key);
  void SetVelodyneScans(const std::filesystem::path& velodyne_dir);
  // Raw layout: ground truth from oxts/data when present (needs cam_from_velo_).
  void LoadOxtsGroundTruth();

  KittiLayout layout_ = KittiLayout::kOdometry;
  std::filesystem::path folder_;
  std::vector<std::filesystem::path> left_images_;
  std::vector<std::filesystem::path> right_images_;
  std::vector<std::optional<std::filesystem::path>> velodyne_scans_;
  std::vector<double> timestamps_;
  StereoCamera camera_;
  std::optional<Rigid3d> cam_from_velo_;
  std::filesystem::path velo_calibration_path_;    // where cam_from_velo_ comes from, or would
  std::filesystem::path camera_calibration_path_;  // where camera_ comes from
  std::optional<std::vector<Rigid3d>> ground_truth_;
};

// One Velodyne scan: float32 x, y, z, reflectance per point (sensor frame: x forward, y left,
// z up). Throws InputError if the file is missing or its size is not a multiple of 16 bytes.
struct VelodyneScan {
  std::vector<Eigen::Vector3d> points;
  std::vector<float> reflectance;
};
VelodyneScan ReadVelodyneScan(const std::filesystem::path& path);
void WriteVelodyneScan(const std::filesystem::path& path, const VelodyneScan& scan);

}  // namespace planeloc
