// Dense disparity of a rectified stereo pair (OpenCV's semi-global block matching), for the
// depth-to-map residual of `planeloc run --prior depth` (prior/depth_prior.h). SGBM runs on the
// pair downsampled by `downsample`: at half resolution a KITTI pair costs about a quarter of the
// full-resolution time, and the residual uses one map point per few pixels anyway.
#pragma once

#include <opencv2/core.hpp>

namespace planeloc {

struct DenseStereoOptions {
  int downsample = 2;         // SGBM on the pair resized by 1/downsample (1, 2 or 4)
  int max_disparity = 128;    // level-0 pixels searched (depth >= fx*b / max_disparity)
  int block_size = 5;         // SGBM block, pixels of the downsampled pair (odd, 3..11)
  int uniqueness_ratio = 10;  // percent by which the best cost must beat the second
  void Check() const;
};

// A disparity image at 1/downsample resolution whose values are level-0 disparities.
struct DenseDisparity {
  cv::Mat disparity;   // CV_32F, level-0 pixels; <= 0: no disparity (occluded, textureless)
  int downsample = 1;  // level-0 pixel (u, v) lies at ((u + 0.5) / s - 0.5, (v + 0.5) / s - 0.5)
  bool empty() const { return disparity.empty(); }
  // Bilinear level-0 disparity at a level-0 pixel; -1 when a neighbour has none or the pixel is
  // outside the image.
  double At(double u, double v) const;
  // True when the 4x4 disparities around level-0 pixel (u, v) all exist and lie on one plane
  // to within `tolerance` level-0 pixels (second differences: a plane's disparity is affine in
  // the pixel). False across depth edges, where interpolation mixes two surfaces.
  bool SmoothAt(double u, double v, double tolerance) const;
};

// `left` and `right`: rectified CV_8UC1 images of the same size (else std::invalid_argument).
// Deterministic (OpenCV's SGBM is single-pass, no thread-order dependence).
DenseDisparity ComputeDenseDisparity(const cv::Mat& left, const cv::Mat& right,
                                     const DenseStereoOptions& options);

}  // namespace planeloc
