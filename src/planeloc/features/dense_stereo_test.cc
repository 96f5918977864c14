#include "planeloc/features/dense_stereo.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "planeloc/features/test_images.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// A fronto-parallel textured plane: the right image is the left one shifted by `shift` pixels,
// so every pixel with both views has the disparity `shift`.
void ShiftedPair(int shift, cv::Mat& left, cv::Mat& right) {
  const cv::Mat texture = testing::RandomTexture(cv::Size(640 + shift, 240), 7, 200, 128, 0.8);
  left = texture(cv::Rect(0, 0, 640, 240)).clone();
  right = texture(cv::Rect(shift, 0, 640, 240)).clone();  // right(u) = left(u + shift)
}

double MedianValid(const DenseDisparity& d, std::vector<double>& values) {
  values.clear();
  for (int v = 40; v < 200; v += 4) {
    for (int u = 160; u < 600; u += 4) {
      const double value = d.At(u, v);
      if (value > 0) values.push_back(value);
    }
  }
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

TEST(DenseStereoTest, RecoversTheShiftOfAPlaneAtEveryDownsampling) {
  cv::Mat left, right;
  ShiftedPair(24, left, right);
  for (int downsample : {1, 2, 4}) {
    DenseStereoOptions options;
    options.downsample = downsample;
    options.max_disparity = 64;
    const DenseDisparity d = ComputeDenseDisparity(left, right, options);
    EXPECT_EQ(d.downsample, downsample);
    EXPECT_EQ(d.disparity.cols, 640 / downsample);
    std::vector<double> values;
    const double median = MedianValid(d, values);
    // Level-0 units at every resolution; SGBM's sub-pixel fit is within a few tenths of a pixel
    // of its own grid, which is `downsample` level-0 pixels.
    EXPECT_NEAR(median, 24.0, 0.25 * downsample) << "downsample " << downsample;
    EXPECT_GT(values.size(), 0.9 * 40 * 110) << "downsample " << downsample;
  }
}

TEST(DenseStereoTest, PixelsWithoutDisparityAreReportedAsNone) {
  cv::Mat left, right;
  ShiftedPair(24, left, right);
  // The left border has no match in the right image (the columns below the disparity range).
  DenseStereoOptions options;
  options.max_disparity = 64;
  const DenseDisparity d = ComputeDenseDisparity(left, right, options);
  EXPECT_EQ(d.At(10, 120), -1);
  EXPECT_EQ(d.At(-3, 120), -1);    // outside the image
  EXPECT_EQ(d.At(300, 1000), -1);  // outside the image
  // A textureless pair has no disparity anywhere.
  const cv::Mat flat(240, 640, CV_8UC1, cv::Scalar(90));
  const DenseDisparity none = ComputeDenseDisparity(flat, flat, options);
  EXPECT_EQ(cv::countNonZero(none.disparity > 0), 0);
}

TEST(DenseStereoTest, RejectsBadOptionsAndImages) {
  cv::Mat left, right;
  ShiftedPair(8, left, right);
  DenseStereoOptions options;
  options.downsample = 3;
  EXPECT_THROW(ComputeDenseDisparity(left, right, options), OptionsError);
  options = {};
  options.block_size = 4;
  EXPECT_THROW(ComputeDenseDisparity(left, right, options), OptionsError);
  EXPECT_THROW(ComputeDenseDisparity(left, right(cv::Rect(0, 0, 320, 240)), DenseStereoOptions{}),
               std::invalid_argument);
}

}  // namespace
}  // namespace planeloc
