#include "planeloc/map/neighborhoods.h"

#include <gtest/gtest.h>
#include <open3d/geometry/KDTreeFlann.h>

#include <algorithm>
#include <random>
#include <stdexcept>

#include "planeloc/map/synthetic_scene_for_test.h"

namespace planeloc {
namespace {

std::vector<std::int32_t> Row(const Neighborhoods& hoods, std::size_t i) {
  std::vector<std::int32_t> row(hoods.indices.begin() + hoods.begin(i),
                                hoods.indices.begin() + hoods.end(i));
  std::sort(row.begin(), row.end());
  return row;
}

std::vector<Eigen::Vector3d> RandomCloud(std::size_t n, double extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-extent, extent);
  std::vector<Eigen::Vector3d> points(n);
  for (auto& p : points) p = {u(rng), u(rng), 0.3 * u(rng)};
  return points;
}

TEST(NeighborhoodsTest, EqualsBruteForceWithSymmetryAndWithoutSelf) {
  auto points = RandomCloud(3000, 3.0, 1);
  points.push_back(points[5]);  // a duplicate: distance 0 is a neighbour, self is not
  const double radius = 0.4;
  const Neighborhoods hoods = FindNeighborhoods(points, radius);
  ASSERT_EQ(hoods.size(), points.size());
  EXPECT_EQ(hoods.radius, radius);
  std::size_t total = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::vector<std::int32_t> expected;
    for (std::size_t j = 0; j < points.size(); ++j) {
      if (j != i && (points[j] - points[i]).squaredNorm() <= radius * radius) {
        expected.push_back(static_cast<std::int32_t>(j));
      }
    }
    ASSERT_EQ(Row(hoods, i), expected) << "point " << i;
    total += expected.size();
  }
  EXPECT_GT(total, 10 * points.size());  // the test is not vacuous
  const auto dup = Row(hoods, points.size() - 1);
  EXPECT_TRUE(std::binary_search(dup.begin(), dup.end(), 5));
}

TEST(NeighborhoodsTest, CapKeepsTheNearestByDistanceThenIndex) {
  const auto points = RandomCloud(2000, 2.0, 7);
  const double radius = 0.5;
  const std::size_t cap = 20;
  const Neighborhoods full = FindNeighborhoods(points, radius);
  const Neighborhoods capped = FindNeighborhoods(points, radius, cap);
  std::size_t rows_capped = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::vector<std::pair<double, std::int32_t>> expected;
    for (auto k = full.begin(i); k < full.end(i); ++k) {
      const std::int32_t j = full.indices[k];
      expected.emplace_back((points[j] - points[i]).squaredNorm(), j);
    }
    std::sort(expected.begin(), expected.end());
    if (expected.size() > cap) {
      expected.resize(cap);
      ++rows_capped;
    }
    std::vector<std::int32_t> nearest;
    for (const auto& e : expected) nearest.push_back(e.second);
    std::sort(nearest.begin(), nearest.end());
    ASSERT_EQ(Row(capped, i), nearest) << "point " << i;
  }
  EXPECT_GT(rows_capped, points.size() / 2);  // the cap is exercised
}

TEST(NeighborhoodsTest, SameSetsAsOpen3dKdTree) {
  const auto scene = testing::SceneBuilder::StreetCorner(0.1, 0.02, 3);
  const double radius = 0.75;
  const Neighborhoods hoods = FindNeighborhoods(scene.points, radius);
  Eigen::MatrixXd data(3, static_cast<Eigen::Index>(scene.points.size()));
  for (std::size_t i = 0; i < scene.points.size(); ++i) {
    data.col(static_cast<Eigen::Index>(i)) = scene.points[i];
  }
  const open3d::geometry::KDTreeFlann tree(data);
  std::vector<int> found;
  std::vector<double> distances2;
  std::size_t differing = 0;
  for (std::size_t i = 0; i < scene.points.size(); i += 7) {
    tree.SearchRadius(scene.points[i], radius, found, distances2);
    std::vector<std::int32_t> expected;
    for (const int j : found) {
      if (static_cast<std::size_t>(j) != i) expected.push_back(j);
    }
    std::sort(expected.begin(), expected.end());
    // Points at exactly the radius may differ (< vs <=); none are expected with noisy points.
    differing += Row(hoods, i) != expected;
  }
  EXPECT_EQ(differing, 0u);
}

TEST(NeighborhoodsTest, MortonOrderIsALocalPermutationAndStable) {
  const auto points = RandomCloud(5000, 10.0, 2);
  const std::vector<std::int32_t> order = MortonOrder(points, 0.5);
  ASSERT_EQ(order.size(), points.size());
  std::vector<std::int32_t> sorted_order = order;
  std::sort(sorted_order.begin(), sorted_order.end());
  for (std::size_t k = 0; k < sorted_order.size(); ++k) ASSERT_EQ(sorted_order[k], (int)k);
  // Consecutive points in Morton order are much closer than consecutive input points.
  double morton_gap = 0.0, input_gap = 0.0;
  for (std::size_t k = 1; k < order.size(); ++k) {
    morton_gap += (points[order[k]] - points[order[k - 1]]).norm();
    input_gap += (points[k] - points[k - 1]).norm();
  }
  EXPECT_LT(morton_gap, 0.2 * input_gap);

  // Sorting again is the identity (what RunTensorVoting relies on to skip its sorted copy), and
  // the sorted cloud has the same neighbour sets under the permutation.
  std::vector<Eigen::Vector3d> sorted(points.size());
  for (std::size_t k = 0; k < order.size(); ++k) sorted[k] = points[order[k]];
  const std::vector<std::int32_t> again = MortonOrder(sorted, 0.5);
  for (std::size_t k = 0; k < again.size(); ++k) ASSERT_EQ(again[k], (int)k);
  const Neighborhoods hoods = FindNeighborhoods(points, 0.5);
  const Neighborhoods sorted_hoods = FindNeighborhoods(sorted, 0.5);
  for (std::size_t k = 0; k < points.size(); ++k) {
    std::vector<std::int32_t> mapped;
    for (const std::int32_t j : Row(sorted_hoods, k)) mapped.push_back(order[j]);
    std::sort(mapped.begin(), mapped.end());
    ASSERT_EQ(mapped, Row(hoods, order[k])) << k;
  }
}

TEST(NeighborhoodsTest, DeterministicAndHandlesEdgeCases) {
  const auto points = RandomCloud(20000, 20.0, 3);
  const Neighborhoods a = FindNeighborhoods(points, 0.6);
  const Neighborhoods b = FindNeighborhoods(points, 0.6);
  EXPECT_EQ(a.offsets, b.offsets);
  EXPECT_EQ(a.indices, b.indices);

  EXPECT_EQ(FindNeighborhoods({}, 1.0).size(), 0u);
  const Neighborhoods single = FindNeighborhoods({{1, 2, 3}}, 1.0);
  ASSERT_EQ(single.size(), 1u);
  EXPECT_EQ(single.end(0), single.begin(0));
  // Points kilometres apart (a map much wider than 2^21 cells of the radius) stay exact.
  const std::vector<Eigen::Vector3d> wide = {{0, 0, 0}, {0.5, 0, 0}, {3e6, 0, 0}, {3e6, 0.5, 0}};
  const Neighborhoods far = FindNeighborhoods(wide, 1e-3 + 0.5);
  EXPECT_EQ(Row(far, 0), std::vector<std::int32_t>{1});
  EXPECT_EQ(Row(far, 2), std::vector<std::int32_t>{3});

  EXPECT_THROW(FindNeighborhoods({{0, 0, std::nan("")}}, 1.0), std::invalid_argument);
  EXPECT_THROW(FindNeighborhoods({{0, 0, 0}}, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace planeloc
