// Rectified pinhole stereo camera.
//
// Built from the rectified projection matrices of a KITTI calibration: P_left = K [I | 0] and
// P_right = K [I | -b e_x] (KITTI stores P1(0,3) = -fx * b, so b = -P1(0,3) / P1(0,0) relative
// to P0). Pixel coordinates: u right, v down, origin at the centre of the top-left pixel.
// A point x_cam (left camera frame, z forward) projects to
//   u_L = fx x / z + cx,  v = fy y / z + cy,  u_R = u_L - fx b / z.
#pragma once

#include <Eigen/Core>
#include <optional>

namespace planeloc {

struct StereoCamera {
  double fx = 0, fy = 0, cx = 0, cy = 0;  // pixels
  double baseline = 0;                    // metres, > 0: right camera at +baseline along x
  int width = 0, height = 0;              // pixels

  // From rectified 3x4 projection matrices of the left and right camera. The left matrix may
  // carry its own x offset (KITTI P2/P3 do); only the relative offset defines the baseline.
  // Throws std::invalid_argument if the matrices are not rectified-pinhole-shaped or b <= 0.
  static StereoCamera FromProjections(const Eigen::Matrix<double, 3, 4>& p_left,
                                      const Eigen::Matrix<double, 3, 4>& p_right, int width,
                                      int height);

  Eigen::Matrix3d K() const;
  double BaselineTimesFx() const { return fx * baseline; }  // "bf" in ORB-SLAM2, pixels*metres

  // Left-image pixel of a point in the left camera frame; nullopt if z <= 0.
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& point_in_cam) const;
  // (u_L, v, u_R) of a point in the left camera frame; nullopt if z <= 0.
  std::optional<Eigen::Vector3d> ProjectStereo(const Eigen::Vector3d& point_in_cam) const;
  // Point in the left camera frame from a left pixel and its depth z (metres).
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel, double depth) const;
  // Depth from disparity d = u_L - u_R (pixels, > 0).
  double DepthFromDisparity(double disparity) const { return BaselineTimesFx() / disparity; }
  bool InImage(const Eigen::Vector2d& pixel, double border = 0.0) const;

  // Throws std::invalid_argument naming the bad field.
  void Check() const;
};

}  // namespace planeloc
