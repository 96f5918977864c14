// Deterministic synthetic images for the features tests (header-only, used by *_test.cc).
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace planeloc::testing {

// Multi-scale blocky random texture: corners at every pyramid level. `amplitude` is the grey
// range of the texture around `mean`; `blur_sigma` > 0 smooths it (for sub-pixel warps).
inline cv::Mat RandomTexture(cv::Size size, uint64_t seed, double amplitude = 200.0,
                             double mean = 128.0, double blur_sigma = 0.0) {
  cv::RNG rng(seed);
  cv::Mat sum = cv::Mat::zeros(size, CV_32F);
  const int block_sizes[] = {3, 5, 9, 17, 31};
  for (int block : block_sizes) {
    cv::Mat small(size.height / block + 1, size.width / block + 1, CV_32F);
    rng.fill(small, cv::RNG::UNIFORM, -0.5, 0.5);
    cv::Mat large;
    cv::resize(small, large, cv::Size(small.cols * block, small.rows * block), 0, 0,
               cv::INTER_NEAREST);
    sum += large(cv::Rect(0, 0, size.width, size.height));
  }
  if (blur_sigma > 0) cv::GaussianBlur(sum, sum, cv::Size(0, 0), blur_sigma);
  cv::Mat grey;
  // The sum of 5 uniform(-0.5, 0.5) has a standard deviation of ~0.65.
  sum.convertTo(grey, CV_8U, amplitude / 2.6, mean);
  return grey;
}

}  // namespace planeloc::testing
