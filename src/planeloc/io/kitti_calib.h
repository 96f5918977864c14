// KITTI calibration files: `key: v1 v2 ...` per line, used by both dataset layouts.
//   odometry  calib.txt            P0..P3 (rectified 3x4 projections), Tr (velo -> cam0, 3x4)
//   raw       calib_cam_to_cam.txt P_rect_0X, S_rect_0X, R_rect_00, ... (and a `calib_time:` line)
//             calib_velo_to_cam.txt, calib_imu_to_velo.txt   R (3x3 row-major), T (3)
// Values are parsed on request so that non-numeric lines (`calib_time`) never get in the way; every
// error is an InputError naming the file and the 1-based line of the key.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"

namespace planeloc {

using Matrix3x4d = Eigen::Matrix<double, 3, 4>;

class KittiCalibFile {
 public:
  // Reads the `key: values` lines. Throws InputError if the file is missing or unreadable, or a
  // non-empty line has no `key:`.
  static KittiCalibFile Read(const std::filesystem::path& path);

  const std::filesystem::path& path() const { return path_; }
  bool Has(const std::string& key) const { return entries_.count(key) > 0; }
  // 1-based line of `key`, 0 when absent.
  int LineOf(const std::string& key) const;

  // Exactly `count` finite numbers stored under `key`. Throws InputError (file, line) when the key
  // is absent, or there are too few/many values or a value is not a finite number.
  std::vector<double> Numbers(const std::string& key, std::size_t count) const;
  Matrix3x4d Matrix3x4(const std::string& key) const;     // 12 numbers, row-major
  Eigen::Matrix3d Matrix3(const std::string& key) const;  // 9 numbers, row-major
  Eigen::Vector3d Vector3(const std::string& key) const;  // 3 numbers
  // A rigid transform from a row-major rotation `r_key` and translation `t_key` (raw calib files).
  // Throws InputError if the rotation is not orthonormal within 1e-3.
  Rigid3d RigidFromRT(const std::string& r_key, const std::string& t_key) const;
  // A rigid transform from a 3x4 row-major [R|t] under `key` (odometry `Tr`), same check.
  Rigid3d RigidFrom3x4(const std::string& key) const;

 private:
  struct Entry {
    std::string values;
    int line = 0;
  };
  Rigid3d ToRigid(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation,
                  const std::string& key) const;

  std::filesystem::path path_;
  std::map<std::string, Entry> entries_;
};

// Translation of rectified camera k relative to the rectified reference camera (cam0), read from
// its projection P_k = K [I | t]: t = (P_k(0,3) / fx, 0, 0). Only the x offset is used, as pykitti
// and the stereo model (all rectified cameras on one x axis) do; the y/z entries of P2/P3 amount to
// < 3 mm and are ignored. Returns cam_k_from_cam0.
Rigid3d RectifiedCameraFromCam0(const Matrix3x4d& projection);

// Stereo camera from two projections of `calib`. Wraps StereoCamera::FromProjections so that a bad
// pair (zero/negative baseline, different intrinsics) is an InputError naming the file and the
// line of the right camera's matrix.
StereoCamera StereoCameraFromCalib(const KittiCalibFile& calib, const std::string& left_key,
                                   const std::string& right_key, int width, int height);

// KITTI odometry calib.txt: P0..P3 and the optional Tr (velo -> cam0).
struct KittiOdometryCalib {
  Matrix3x4d p[4];
  bool has_cam0_from_velo = false;
  Rigid3d cam0_from_velo;
};
KittiOdometryCalib ReadKittiOdometryCalib(const std::filesystem::path& path);

}  // namespace planeloc
