#include "planeloc/prior/map_cloud_index.h"

#include <algorithm>
#include <cmath>

#include "planeloc/util/error.h"

namespace planeloc {

MapCloudIndex::MapCloudIndex(std::vector<Eigen::Vector3d> points, double bucket_size)
    : points_(std::move(points)), bucket_size_(bucket_size) {
  if (!(bucket_size_ > 0)) throw OptionsError("MapCloudIndex: bucket_size must be > 0");
  for (int i = 0; i < static_cast<int>(points_.size()); ++i) {
    buckets_[Key(Bucket(points_[i]))].push_back(i);
  }
}

Eigen::Vector3i MapCloudIndex::Bucket(const Eigen::Vector3d& p) const {
  return (p / bucket_size_).array().floor().cast<int>();
}

std::uint64_t MapCloudIndex::Key(const Eigen::Vector3i& bucket) {
  // 21 bits per axis: +-1e6 buckets, far beyond any map at metre-sized buckets.
  const auto field = [](int v) { return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1FFFFF; };
  return field(bucket.x()) | (field(bucket.y()) << 21) | (field(bucket.z()) << 42);
}

std::vector<int> MapCloudIndex::Near(const Eigen::Vector3d& center, double radius) const {
  std::vector<int> result;
  const Eigen::Vector3i low = Bucket(center - Eigen::Vector3d::Constant(radius));
  const Eigen::Vector3i high = Bucket(center + Eigen::Vector3d::Constant(radius));
  const double radius2 = radius * radius;
  for (int x = low.x(); x <= high.x(); ++x) {
    for (int y = low.y(); y <= high.y(); ++y) {
      for (int z = low.z(); z <= high.z(); ++z) {
        const auto it = buckets_.find(Key(Eigen::Vector3i(x, y, z)));
        if (it == buckets_.end()) continue;
        for (int i : it->second) {
          if ((points_[i] - center).squaredNorm() <= radius2) result.push_back(i);
        }
      }
    }
  }
  std::sort(result.begin(), result.end());
  return result;
}

}  // namespace planeloc
