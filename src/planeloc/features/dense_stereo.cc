#include "planeloc/features/dense_stereo.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "planeloc/util/error.h"

namespace planeloc {

void DenseStereoOptions::Check() const {
  if (downsample != 1 && downsample != 2 && downsample != 4) {
    throw OptionsError("DenseStereoOptions.downsample must be 1, 2 or 4");
  }
  if (max_disparity < 16 * downsample) {
    throw OptionsError("DenseStereoOptions.max_disparity must be >= 16 x downsample");
  }
  if (block_size < 3 || block_size > 11 || block_size % 2 == 0) {
    throw OptionsError("DenseStereoOptions.block_size must be odd, in [3, 11]");
  }
  if (uniqueness_ratio < 0 || uniqueness_ratio > 100) {
    throw OptionsError("DenseStereoOptions.uniqueness_ratio must be in [0, 100]");
  }
}

double DenseDisparity::At(double u, double v) const {
  const double x = (u + 0.5) / downsample - 0.5;
  const double y = (v + 0.5) / downsample - 0.5;
  const int x0 = static_cast<int>(std::floor(x));
  const int y0 = static_cast<int>(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= disparity.cols || y0 + 1 >= disparity.rows) return -1;
  const float* row0 = disparity.ptr<float>(y0);
  const float* row1 = disparity.ptr<float>(y0 + 1);
  const double d00 = row0[x0], d01 = row0[x0 + 1], d10 = row1[x0], d11 = row1[x0 + 1];
  if (d00 <= 0 || d01 <= 0 || d10 <= 0 || d11 <= 0) return -1;
  const double fx = x - x0, fy = y - y0;
  return (1 - fy) * ((1 - fx) * d00 + fx * d01) + fy * ((1 - fx) * d10 + fx * d11);
}

bool DenseDisparity::SmoothAt(double u, double v, double tolerance) const {
  const int x0 = static_cast<int>(std::floor((u + 0.5) / downsample - 0.5));
  const int y0 = static_cast<int>(std::floor((v + 0.5) / downsample - 0.5));
  if (x0 < 1 || y0 < 1 || x0 + 2 >= disparity.cols || y0 + 2 >= disparity.rows) return false;
  float block[4][4];
  for (int r = 0; r < 4; ++r) {
    const float* row = disparity.ptr<float>(y0 - 1 + r);
    for (int c = 0; c < 4; ++c) {
      block[r][c] = row[x0 - 1 + c];
      if (block[r][c] <= 0) return false;
    }
  }
  for (int i = 0; i < 4; ++i) {
    for (int j = 1; j < 3; ++j) {
      if (std::abs(block[i][j - 1] - 2 * block[i][j] + block[i][j + 1]) > tolerance) return false;
      if (std::abs(block[j - 1][i] - 2 * block[j][i] + block[j + 1][i]) > tolerance) return false;
    }
  }
  return true;
}

DenseDisparity ComputeDenseDisparity(const cv::Mat& left, const cv::Mat& right,
                                     const DenseStereoOptions& options) {
  options.Check();
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1 || left.size() != right.size()) {
    throw std::invalid_argument("ComputeDenseDisparity: two CV_8UC1 images of the same size");
  }
  cv::Mat small_left = left, small_right = right;
  if (options.downsample > 1) {
    const cv::Size size(left.cols / options.downsample, left.rows / options.downsample);
    cv::resize(left, small_left, size, 0, 0, cv::INTER_AREA);
    cv::resize(right, small_right, size, 0, 0, cv::INTER_AREA);
  }
  // SGBM's disparity count must be a multiple of 16 at the resolution it runs on.
  const int num_disparities = ((options.max_disparity / options.downsample + 15) / 16) * 16;
  const int area = options.block_size * options.block_size;
  // All eight path directions (MODE_HH): the single-pass five-direction mode has no path from
  // below, and on the road, whose disparity grows down the image, its paths from the rows above
  // pull every pixel towards smaller disparities: -1.1 px on the road of `small` seed 3 against
  // -0.2 to -0.5 px with eight (docs/depth-prior.md).
  cv::Ptr<cv::StereoSGBM> sgbm = cv::StereoSGBM::create(
      /*minDisparity=*/0, num_disparities, options.block_size, /*P1=*/8 * area, /*P2=*/32 * area,
      /*disp12MaxDiff=*/1, /*preFilterCap=*/31, options.uniqueness_ratio,
      /*speckleWindowSize=*/100, /*speckleRange=*/2, cv::StereoSGBM::MODE_HH);
  cv::Mat fixed_point;  // CV_16S, 4 fractional bits
  sgbm->compute(small_left, small_right, fixed_point);

  DenseDisparity result;
  result.downsample = options.downsample;
  // Level-0 pixels: a disparity of d at 1/s resolution is s*d at full resolution.
  fixed_point.convertTo(result.disparity, CV_32F, options.downsample / 16.0);
  // Invalid pixels are negative (minDisparity - 1, scaled); 0 is "infinitely far": both are
  // "no disparity" for the residual.
  cv::threshold(result.disparity, result.disparity, 0.0, -1.0, cv::THRESH_TOZERO);
  return result;
}

}  // namespace planeloc
