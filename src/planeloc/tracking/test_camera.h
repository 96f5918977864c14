// A round-numbered rectified stereo camera for tracking tests on hand-made features, and the
// random descriptors and points those tests draw.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <random>
#include <vector>

#include "planeloc/geometry/camera.h"

namespace planeloc::testing {

inline StereoCamera RoundStereoCamera() {
  return StereoCamera{
      .fx = 700, .fy = 700, .cx = 600, .cy = 185, .baseline = 0.5, .width = 1200, .height = 370};
}

// n random 32-byte ORB descriptors.
inline cv::Mat RandomDescriptors(int n, std::mt19937& rng) {
  cv::Mat d(n, 32, CV_8U);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < 32; ++c) d.at<uint8_t>(r, c) = static_cast<uint8_t>(byte(rng));
  }
  return d;
}

// n points in front of a camera at the origin: x in [-6, 6], y in [-2, 2], z in [5, 15] m.
inline std::vector<Eigen::Vector3d> RandomPoints(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> x(-6, 6), y(-2, 2), z(5, 15);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) points.emplace_back(x(rng), y(rng), z(rng));
  return points;
}

}  // namespace planeloc::testing
