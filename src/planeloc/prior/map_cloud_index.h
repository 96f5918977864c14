// The LiDAR map's points, voxelized once and bucketed in a coarse grid, so that the points near
// the camera (the depth residual's candidates, prior/depth_prior.h) cost a few buckets per frame
// instead of a pass over the map.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "planeloc/io/point_cloud.h"

namespace planeloc {

class MapCloudIndex {
 public:
  // `points`: the map (map frame, metres), already voxelized by the caller (ReadPointCloud's
  // voxel_size). `bucket_size`: edge of the grid's cubes (m, > 0); a query visits the cubes that
  // overlap its ball.
  explicit MapCloudIndex(std::vector<Eigen::Vector3d> points, double bucket_size = 8.0);

  std::size_t size() const { return points_.size(); }
  const Eigen::Vector3d& point(int index) const { return points_[index]; }
  // Indices of the points within `radius` of `center`, ascending (deterministic).
  std::vector<int> Near(const Eigen::Vector3d& center, double radius) const;

 private:
  Eigen::Vector3i Bucket(const Eigen::Vector3d& p) const;
  static std::uint64_t Key(const Eigen::Vector3i& bucket);

  std::vector<Eigen::Vector3d> points_;
  double bucket_size_;
  std::unordered_map<std::uint64_t, std::vector<int>> buckets_;
};

}  // namespace planeloc
