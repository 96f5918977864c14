// A round-numbered rectified stereo camera for tracking tests on hand-made features, and the
// random descriptors, points and features those tests draw.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <random>
#include <vector>

#include "planeloc/features/stereo_matcher.h"
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

// Features of the given camera-frame points seen by `camera` (stereo where depth > 0), one
// keypoint per point at level 0 with the given descriptors.
inline StereoFeatures FeaturesOf(const std::vector<Eigen::Vector3d>& points_in_cam,
                                 const cv::Mat& descriptors, const StereoCamera& camera) {
  StereoFeatures f;
  f.left.descriptors = descriptors.clone();
  for (const Eigen::Vector3d& p : points_in_cam) {
    const Eigen::Vector3d uvr = *camera.ProjectStereo(p);
    f.left.keypoints.emplace_back(cv::Point2f(uvr.x(), uvr.y()), 31.f, 45.f, 0.f, 0);
    f.u_right.push_back(static_cast<float>(uvr.z()));
    f.depth.push_back(static_cast<float>(p.z()));
  }
  return f;
}

}  // namespace planeloc::testing
