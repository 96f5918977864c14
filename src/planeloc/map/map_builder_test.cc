#include "planeloc/map/map_builder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "planeloc/map/neighborhoods.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

// A 10 m x 10 m grid at z = -1.7 (road below the sensor), 5 cm spacing, in the Velodyne frame.
std::vector<Eigen::Vector3d> RoadScan() {
  std::vector<Eigen::Vector3d> points;
  for (double x = -5.0; x < 5.0; x += 0.05) {
    for (double y = -5.0; y < 5.0; y += 0.05) points.emplace_back(x, y, -1.7);
  }
  return points;
}

TEST(MapAccumulatorTest, TransformsFiltersRangeAndDownsamples) {
  MapBuildOptions options;
  options.voxel_size = 0.2;
  options.min_range = 2.0;
  options.max_range = 4.0;
  options.show_progress = false;
  MapAccumulator accumulator(options);
  const Rigid3d world_from_velo(Eigen::Quaterniond::Identity(), Eigen::Vector3d(100, 0, 10));
  accumulator.AddScan(RoadScan(), world_from_velo);
  accumulator.AddScan(RoadScan(), world_from_velo);  // the same points again: no growth
  EXPECT_EQ(accumulator.scans(), 2u);
  const PointCloud map = accumulator.Finish();
  ASSERT_FALSE(map.empty());
  // Range ring 2..4 m around (100, 0) of area pi (4^2 - 1.7^2 ... ) ~ 40 m^2 at 0.2 m voxels.
  EXPECT_LT(map.size(), 1500u);
  EXPECT_GT(map.size(), 500u);
  for (const auto& p : map.points) {
    EXPECT_NEAR(p.z(), 10.0 - 1.7, 1e-9);
    const double r = Eigen::Vector3d(p.x() - 100.0, p.y(), -1.7).norm();
    EXPECT_GE(r, 2.0 - 0.2);
    EXPECT_LE(r, 4.0 + 0.2);
  }
}

// Damaged scans are counted, not silently dropped (issue 37): an empty scan, an all-NaN one, one
// scaled x 1e30 (every point beyond max_range) and a road scan with 3 NaN/Inf points.
TEST(MapAccumulatorTest, CountsScansWithoutPointsAndNonFinitePoints) {
  MapBuildOptions options;
  options.show_progress = false;
  MapAccumulator accumulator(options);
  const Rigid3d identity;
  accumulator.AddScan({}, identity);
  accumulator.AddScan(std::vector<Eigen::Vector3d>(100, Eigen::Vector3d::Constant(NAN)), identity);
  std::vector<Eigen::Vector3d> scaled = RoadScan();
  for (auto& p : scaled) p *= 1e30;
  accumulator.AddScan(scaled, identity);
  std::vector<Eigen::Vector3d> damaged = RoadScan();
  damaged[0].x() = NAN;
  damaged[1].y() = INFINITY;
  damaged[2].z() = -INFINITY;
  accumulator.AddScan(damaged, identity);
  EXPECT_EQ(accumulator.scans(), 4u);
  EXPECT_EQ(accumulator.empty_scans(), 3u);
  EXPECT_EQ(accumulator.non_finite_points(), 103u);
  const std::size_t road = RoadScan().size();  // 40 000
  EXPECT_EQ(accumulator.scan_points(), 100 + 2 * road);
  // The scaled scan lies beyond max_range; of the road, the points within min_range (2 m) of the
  // sensor go too (none of the 3 damaged ones, in a far corner).
  const auto scan = RoadScan();
  const auto near = static_cast<std::size_t>(std::count_if(
      scan.begin(), scan.end(), [&](const Eigen::Vector3d& p) { return p.norm() < 2.0; }));
  EXPECT_GT(near, 1000u);
  EXPECT_EQ(accumulator.out_of_range_points(), road + near);
  const PointCloud map = accumulator.Finish();
  EXPECT_FALSE(map.empty());
  for (const auto& p : map.points) EXPECT_TRUE(p.allFinite());
}

TEST(MapBuildCountsTest, FromCommentsFindsTheTaggedJsonOnly) {
  MapBuildCounts counts;
  counts.scans = 8;
  counts.empty_scans = 1;
  const std::vector<std::string> comments = {"planeloc", "planeloc map build {broken",
                                             kMapBuildCommentTag + counts.ToJson().dump()};
  const auto read = MapBuildCountsFromComments(comments);
  ASSERT_TRUE(read.has_value());
  EXPECT_EQ((*read)["scans"], 8);
  EXPECT_EQ((*read)["empty_scans"], 1);
  EXPECT_FALSE(MapBuildCountsFromComments({"planeloc", "site 4"}).has_value());
}

TEST(MapAccumulatorTest, CompactionKeepsTheMapBounded) {
  MapBuildOptions options;
  options.voxel_size = 0.1;
  options.buffer_points = 1000;
  options.max_range = 100.0;
  MapAccumulator accumulator(options);
  for (int i = 0; i < 10; ++i) {
    accumulator.AddScan(RoadScan(),
                        Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.01 * i, 0, 0)));
  }
  const PointCloud map = accumulator.Finish();
  // 10 m x 10.1 m at 0.1 m voxels minus the 2 m hole: ~ 10 000 points, not 10 scans' worth.
  EXPECT_LT(map.size(), 11000u);
  EXPECT_GT(map.size(), 8000u);
  // Written in Morton order of the tensor-voting radius, so `map planes` needs no sorted copy.
  const std::vector<std::int32_t> order = MortonOrder(map.points, options.sort_cell);
  for (std::size_t k = 0; k < order.size(); ++k) ASSERT_EQ(order[k], static_cast<int>(k));
}

TEST(MapBuildOptionsTest, Check) {
  MapBuildOptions options;
  options.every = 0;
  EXPECT_THROW(options.Check(), OptionsError);
  options = MapBuildOptions();
  options.max_range = 1.0;
  EXPECT_THROW(options.Check(), OptionsError);
  options = MapBuildOptions();
  options.sort_cell = -1.0;
  EXPECT_THROW(options.Check(), OptionsError);
}

}  // namespace
}  // namespace planeloc
