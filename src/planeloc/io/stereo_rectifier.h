// Rectification of raw (distorted, unaligned) stereo pairs on load, for rigs described the way
// ORB-SLAM2 (LEFT/RIGHT K, D, R, P: EuRoC-style) or ORB-SLAM3 (two pinhole cameras with radial-
// tangential distortion and Stereo.T_c1_c2) settings files describe them.
//
// The undistort-rectify maps are computed once (cv::initUndistortRectifyMap); each frame costs
// one cv::remap per image (bilinear; cost in bench/rectify_bench.cc, docs/experiments.md). The
// rectified images have the raw images' size, and camera() is the rectified stereo camera
// (P_left = K [I | 0], P_right = K [I | -fx b e_x]).
#pragma once

#include <opencv2/core.hpp>

#include "planeloc/geometry/camera.h"
#include "planeloc/io/kitti_sequence.h"

namespace planeloc {

// One raw pinhole camera: intrinsics K (3x3) and OpenCV radial-tangential distortion D
// (k1 k2 p1 p2 [k3], 4 or 5 values, 1xN), both CV_64F.
struct RawCamera {
  cv::Mat k;
  cv::Mat d;
};

class StereoRectifier {
 public:
  // From a given rectification (ORB-SLAM2's LEFT.R/P, RIGHT.R/P): R (3x3) rotates a raw camera
  // into the rectified frame, P (3x4) is the rectified projection. P_right(0,3) = -fx * b.
  // Throws std::invalid_argument if the shapes are wrong or P does not describe a rectified pair.
  static StereoRectifier FromRectification(const RawCamera& left, const cv::Mat& left_r,
                                           const cv::Mat& left_p, const RawCamera& right,
                                           const cv::Mat& right_r, const cv::Mat& right_p,
                                           cv::Size size);
  // From the extrinsics (ORB-SLAM3's Stereo.T_c1_c2 = left_from_right, 4x4): cv::stereoRectify
  // with zero disparity at infinity and alpha 0 (only valid pixels), as ORB-SLAM3 does.
  static StereoRectifier FromExtrinsics(const RawCamera& left, const RawCamera& right,
                                        const cv::Mat& left_from_right, cv::Size size);

  const StereoCamera& camera() const { return camera_; }
  cv::Size size() const { return size_; }
  // Rectifies a raw pair of size(). Throws std::invalid_argument on another size.
  StereoPair Rectify(const StereoPair& raw) const;
  // The calibration it was built from (for writing it back).
  const RawCamera& left() const { return left_; }
  const RawCamera& right() const { return right_; }
  const cv::Mat& left_r() const { return left_r_; }  // raw left -> rectified left rotation
  const cv::Mat& right_r() const { return right_r_; }
  const cv::Mat& left_p() const { return left_p_; }  // rectified projections, 3x4
  const cv::Mat& right_p() const { return right_p_; }
  // The rectified left/right pixel of a raw pixel (for tests and diagnostics).
  cv::Point2d RectifyLeftPixel(const cv::Point2d& raw) const;
  cv::Point2d RectifyRightPixel(const cv::Point2d& raw) const;

 private:
  StereoRectifier() = default;
  void Init(const RawCamera& left, const cv::Mat& left_r, const cv::Mat& left_p,
            const RawCamera& right, const cv::Mat& right_r, const cv::Mat& right_p, cv::Size size);

  StereoCamera camera_;
  cv::Size size_;
  RawCamera left_, right_;
  cv::Mat left_r_, left_p_, right_r_, right_p_;
  cv::Mat left_map1_, left_map2_, right_map1_, right_map2_;  // CV_16SC2 + CV_16UC1
};

}  // namespace planeloc
