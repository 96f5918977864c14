#include "planeloc/tracking/frame.h"

#include <algorithm>
#include <cmath>

namespace planeloc {

FeatureGrid::FeatureGrid(const std::vector<cv::KeyPoint>& keypoints, int width, int height)
    : cols_(std::max(1, (width + kCellSize - 1) / kCellSize)),
      rows_(std::max(1, (height + kCellSize - 1) / kCellSize)),
      cells_(static_cast<std::size_t>(cols_ * rows_)) {
  for (int i = 0; i < static_cast<int>(keypoints.size()); ++i) {
    const int cx = std::clamp(static_cast<int>(keypoints[i].pt.x) / kCellSize, 0, cols_ - 1);
    const int cy = std::clamp(static_cast<int>(keypoints[i].pt.y) / kCellSize, 0, rows_ - 1);
    cells_[cy * cols_ + cx].push_back(i);
  }
}

std::vector<int> FeatureGrid::InArea(const std::vector<cv::KeyPoint>& keypoints, double u, double v,
                                     double radius, int min_level, int max_level) const {
  std::vector<int> result;
  if (cells_.empty()) return result;
  const int x0 = static_cast<int>(std::floor((u - radius) / kCellSize));
  const int x1 = static_cast<int>(std::floor((u + radius) / kCellSize));
  const int y0 = static_cast<int>(std::floor((v - radius) / kCellSize));
  const int y1 = static_cast<int>(std::floor((v + radius) / kCellSize));
  if (x1 < 0 || y1 < 0 || x0 >= cols_ || y0 >= rows_) return result;
  for (int cy = std::max(0, y0); cy <= std::min(rows_ - 1, y1); ++cy) {
    for (int cx = std::max(0, x0); cx <= std::min(cols_ - 1, x1); ++cx) {
      for (int i : cells_[cy * cols_ + cx]) {
        const cv::KeyPoint& kp = keypoints[i];
        if (kp.octave < min_level || (max_level >= 0 && kp.octave > max_level)) continue;
        if (std::abs(kp.pt.x - u) <= radius && std::abs(kp.pt.y - v) <= radius) {
          result.push_back(i);
        }
      }
    }
  }
  std::sort(result.begin(), result.end());
  return result;
}

Frame::Frame(int frame_id, double time, StereoFeatures stereo_features, const StereoCamera& camera)
    : id(frame_id), timestamp(time), features(std::move(stereo_features)) {
  features.left.pyramid.clear();
  features.dense = {};
  grid = FeatureGrid(features.left.keypoints, camera.width, camera.height);
  map_point_ids.assign(features.left.keypoints.size(), -1);
  outlier.assign(features.left.keypoints.size(), false);
}

Eigen::Vector3d Frame::UnprojectToWorld(int i, const StereoCamera& camera) const {
  const cv::KeyPoint& kp = keypoint(i);
  const Eigen::Vector3d in_cam =
      camera.Unproject(Eigen::Vector2d(kp.pt.x, kp.pt.y), features.depth[i]);
  return cam_from_world.Inverse() * in_cam;
}

int Frame::NumTracked() const {
  int n = 0;
  for (int i = 0; i < size(); ++i) n += (map_point_ids[i] >= 0 && !outlier[i]) ? 1 : 0;
  return n;
}

}  // namespace planeloc
