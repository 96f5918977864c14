#include "planeloc/prior/map_cloud_index.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// The buckets return exactly what a pass over every point returns, across bucket borders and on
// both sides of the origin.
TEST(MapCloudIndexTest, NearEqualsABruteForcePass) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> coordinate(-60.0, 60.0);
  std::vector<Eigen::Vector3d> points(5000);
  for (Eigen::Vector3d& p : points) p = {coordinate(rng), coordinate(rng), coordinate(rng) / 10};
  const MapCloudIndex index(points, 8.0);
  ASSERT_EQ(index.size(), points.size());
  for (const Eigen::Vector3d& center :
       {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(-31.7, 12.2, 1.0), Eigen::Vector3d(8, -8, 0)}) {
    for (double radius : {0.5, 7.9, 8.0, 25.0}) {
      std::vector<int> expected;
      for (int i = 0; i < static_cast<int>(points.size()); ++i) {
        if ((points[i] - center).norm() <= radius) expected.push_back(i);
      }
      EXPECT_EQ(index.Near(center, radius), expected) << center.transpose() << " r " << radius;
    }
  }
  EXPECT_TRUE(index.Near(Eigen::Vector3d(500, 0, 0), 20).empty());
}

TEST(MapCloudIndexTest, RejectsABucketOfNoSize) {
  EXPECT_THROW(MapCloudIndex({Eigen::Vector3d::Zero()}, 0.0), OptionsError);
}

}  // namespace
}  // namespace planeloc
