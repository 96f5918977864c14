// Voxel filtering of point clouds in one pass with bounded memory: points (streamed from a file
// or given as a cloud) are averaged per cubic voxel, so the memory follows the number of occupied
// voxels, not the number of input points. Used by ReadPointCloud (--voxel while reading) and by
// `map planes` before tensor voting.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "planeloc/io/point_cloud.h"

namespace planeloc {

// Voxels are cubes of side `voxel_size` (metres) aligned with the frame's origin: voxel
// floor(p / voxel_size). Each occupied voxel gives the centroid of its points (and the mean
// colour). Filtering twice with the same size is the identity (centroids stay in their voxel), and
// the output is sorted along a Z-order curve of the voxel coordinates, so it does not depend on
// the input order and neighbouring voxels are close in memory.
// voxel_size == 0 keeps every point in input order.
class VoxelAccumulator {
 public:
  // Throws OptionsError when voxel_size is negative or not finite.
  explicit VoxelAccumulator(double voxel_size);

  // Hint for voxel_size == 0 (the points are stored as they come).
  void Reserve(std::size_t points);
  // `color` may be null; colours are kept only when every point has one. `point` must be finite.
  void Add(const Eigen::Vector3d& point, const Eigen::Vector3d* color);
  std::size_t added() const { return added_; }
  // The filtered cloud; `source_points` = added(). The accumulator is empty afterwards.
  PointCloud Finish();

 private:
  struct Key {
    std::int64_t x, y, z;
    bool operator==(const Key& other) const { return x == other.x && y == other.y && z == other.z; }
  };
  struct KeyHash {
    std::size_t operator()(const Key& key) const;
  };
  struct Sum {
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    Eigen::Vector3f color = Eigen::Vector3f::Zero();
    std::uint32_t count = 0;
  };

  double voxel_size_;
  std::size_t added_ = 0;
  bool all_colored_ = true;
  PointCloud raw_;  // voxel_size == 0
  std::unordered_map<Key, Sum, KeyHash> voxels_;
};

// The cloud filtered as above (a copy when voxel_size == 0). Keeps dropped_invalid of the input;
// source_points = the input's source_points, or its size when that is 0.
PointCloud VoxelFilter(const PointCloud& cloud, double voxel_size);

}  // namespace planeloc
