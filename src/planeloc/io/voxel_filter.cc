#include "planeloc/io/voxel_filter.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <string>
#include <tuple>

#include "planeloc/geometry/morton.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {}  // namespace

VoxelAccumulator::VoxelAccumulator(double voxel_size) : voxel_size_(voxel_size) {
  if (!(voxel_size >= 0.0) || !std::isfinite(voxel_size)) {
    throw OptionsError("voxel size must be finite and >= 0 (metres), got " +
                       std::to_string(voxel_size));
  }
}

std::size_t VoxelAccumulator::KeyHash::operator()(const Key& key) const {
  // Large odd multipliers (as in spatial hashing, Teschner et al. 2003) mixed into 64 bits.
  const auto h = static_cast<std::uint64_t>(key.x) * 73856093ULL ^
                 static_cast<std::uint64_t>(key.y) * 19349669ULL ^
                 static_cast<std::uint64_t>(key.z) * 83492791ULL;
  return static_cast<std::size_t>(h ^ (h >> 29));
}

void VoxelAccumulator::Reserve(std::size_t points) {
  if (voxel_size_ == 0.0) raw_.points.reserve(points);
}

void VoxelAccumulator::Add(const Eigen::Vector3d& point, const Eigen::Vector3d* color) {
  ++added_;
  all_colored_ = all_colored_ && color != nullptr;
  if (voxel_size_ == 0.0) {
    raw_.points.push_back(point);
    if (all_colored_) raw_.colors.push_back(*color);
    return;
  }
  // Clamped to +-2^62 voxels: converting a larger double to int64 is undefined behaviour (a
  // finite point 1e30 m away with --voxel 0.1). Real maps are nowhere near.
  constexpr double kMaxCell = 4611686018427387904.0;  // 2^62
  const Eigen::Vector3d cell = (point / voxel_size_).array().floor().max(-kMaxCell).min(kMaxCell);
  Sum& sum = voxels_[Key{static_cast<std::int64_t>(cell.x()), static_cast<std::int64_t>(cell.y()),
                         static_cast<std::int64_t>(cell.z())}];
  sum.point += point;
  if (all_colored_) sum.color += color->cast<float>();
  ++sum.count;
}

PointCloud VoxelAccumulator::Finish() {
  PointCloud cloud;
  if (voxel_size_ == 0.0) {
    cloud = std::move(raw_);
    raw_ = PointCloud();
    if (!all_colored_) cloud.colors.clear();
  } else {
    // Z-order (Morton) of the voxel coordinates, so that neighbouring voxels are close in memory
    // (tensor voting then needs no sorted copy); coordinates beyond 2^21 voxels from the lowest
    // only lose locality, and ties are broken by the coordinates.
    std::vector<std::tuple<std::uint64_t, Key, Sum>> sorted;
    sorted.reserve(voxels_.size());
    Key lo{INT64_MAX, INT64_MAX, INT64_MAX};
    for (const auto& [key, sum] : voxels_) {
      lo = {std::min(lo.x, key.x), std::min(lo.y, key.y), std::min(lo.z, key.z)};
    }
    for (const auto& [key, sum] : voxels_) {
      // Unsigned differences: key - lo fits 64 unsigned bits, but not always 63 signed ones
      // (voxel indices span +-2^62).
      auto offset = [](std::int64_t k, std::int64_t low) {
        return static_cast<std::uint64_t>(k) - static_cast<std::uint64_t>(low);
      };
      const std::uint64_t morton =
          MortonKey3(offset(key.x, lo.x), offset(key.y, lo.y), offset(key.z, lo.z));
      sorted.emplace_back(morton, key, sum);
    }
    voxels_ = {};
    std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) {
      const Key& ka = std::get<1>(a);
      const Key& kb = std::get<1>(b);
      return std::tie(std::get<0>(a), ka.z, ka.y, ka.x) <
             std::tie(std::get<0>(b), kb.z, kb.y, kb.x);
    });
    cloud.points.reserve(sorted.size());
    for (const auto& [morton, key, sum] : sorted) {
      cloud.points.push_back(sum.point / sum.count);
      if (all_colored_) cloud.colors.push_back((sum.color / sum.count).cast<double>());
    }
  }
  cloud.source_points = added_;
  added_ = 0;
  all_colored_ = true;
  return cloud;
}

PointCloud VoxelFilter(const PointCloud& cloud, double voxel_size) {
  VoxelAccumulator accumulator(voxel_size);
  accumulator.Reserve(cloud.size());
  const bool colored = cloud.has_colors();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    accumulator.Add(cloud.points[i], colored ? &cloud.colors[i] : nullptr);
  }
  PointCloud filtered = accumulator.Finish();
  filtered.source_points = cloud.source_points > 0 ? cloud.source_points : cloud.size();
  filtered.dropped_invalid = cloud.dropped_invalid;
  return filtered;
}

}  // namespace planeloc
