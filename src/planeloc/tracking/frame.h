// One stereo frame being tracked: its features, a cell grid for radius search, its pose and the
// association of each left keypoint with a map point (by id).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "planeloc/features/stereo_matcher.h"
#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"

namespace planeloc {

// Buckets keypoint indices by image cell so that "keypoints within r pixels of (u, v)" costs a
// few cells instead of a scan of all keypoints.
class FeatureGrid {
 public:
  static constexpr int kCellSize = 32;  // pixels

  FeatureGrid() = default;
  FeatureGrid(const std::vector<cv::KeyPoint>& keypoints, int width, int height);

  // Indices of keypoints with |x - u| <= radius, |y - v| <= radius and octave in
  // [min_level, max_level] (max_level < 0: no upper bound), ascending.
  std::vector<int> InArea(const std::vector<cv::KeyPoint>& keypoints, double u, double v,
                          double radius, int min_level = 0, int max_level = -1) const;

 private:
  int cols_ = 0, rows_ = 0;
  std::vector<std::vector<int>> cells_;
};

struct Frame {
  int id = 0;
  double timestamp = 0;  // seconds
  StereoFeatures features;
  FeatureGrid grid;
  Rigid3d cam_from_world;
  std::vector<int> map_point_ids;  // per left keypoint: map point id or -1
  std::vector<bool> outlier;       // per left keypoint, from the last pose optimization

  Frame() = default;
  // Takes the features (drops the image pyramid and dense disparity: frames outlive their
  // images).
  Frame(int id, double timestamp, StereoFeatures features, const StereoCamera& camera);

  int size() const { return static_cast<int>(features.left.keypoints.size()); }
  const cv::KeyPoint& keypoint(int i) const { return features.left.keypoints[i]; }
  cv::Mat descriptor(int i) const { return features.left.descriptors.row(i); }
  bool HasDepth(int i) const { return features.depth[i] > 0; }
  // Left-camera point of a keypoint with stereo depth, in the world frame.
  Eigen::Vector3d UnprojectToWorld(int i, const StereoCamera& camera) const;
  Eigen::Vector3d CameraCenter() const { return cam_from_world.Inverse().translation; }
  // Number of keypoints associated with a map point and not flagged as outliers.
  int NumTracked() const;
};

}  // namespace planeloc
