#include "planeloc/features/keypoint_distribution.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace planeloc {
namespace {

cv::KeyPoint Corner(float x, float y, float response) {
  cv::KeyPoint kp(x, y, 7.0f);
  kp.response = response;
  return kp;
}

TEST(DistributeQuadtree, KeepsEverythingUnderTheTarget) {
  const std::vector<cv::KeyPoint> corners = {Corner(1, 1, 5), Corner(50, 20, 1), Corner(3, 90, 2)};
  EXPECT_EQ(DistributeQuadtree(corners, cv::Rect2f(0, 0, 100, 100), 5),
            (std::vector<int>{0, 1, 2}));
  EXPECT_TRUE(DistributeQuadtree(corners, cv::Rect2f(0, 0, 100, 100), 0).empty());
}

// A dense strong cluster in one corner and weak corners spread elsewhere: a top-N by response
// would take only the cluster; the quadtree gives each region a share and keeps the strongest of
// each node.
TEST(DistributeQuadtree, SpreadsTheBudgetAndKeepsTheStrongestPerNode) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<cv::KeyPoint> corners;
  for (int i = 0; i < 400; ++i) {  // cluster in [0, 40)^2, strong
    corners.push_back(Corner(40 * unit(rng), 40 * unit(rng), 100 + unit(rng)));
  }
  for (int i = 0; i < 400; ++i) {  // spread over [0, 400) x [0, 200), weak
    corners.push_back(Corner(400 * unit(rng), 200 * unit(rng), unit(rng)));
  }
  const cv::Rect2f area(0, 0, 400, 200);
  const std::vector<int> kept = DistributeQuadtree(corners, area, 100);
  EXPECT_GE(kept.size(), 100u);
  EXPECT_LE(kept.size(), 110u);
  EXPECT_TRUE(std::is_sorted(kept.begin(), kept.end()));
  const long in_cluster = std::count_if(kept.begin(), kept.end(), [&](int i) {
    return corners[i].pt.x < 40 && corners[i].pt.y < 40;
  });
  EXPECT_LT(in_cluster, 20);  // the cluster is 2 % of the area
  // Every quadrant of the area gets features.
  for (int q = 0; q < 4; ++q) {
    const float x0 = (q % 2) * 200.0f, y0 = (q / 2) * 100.0f;
    EXPECT_GT(std::count_if(kept.begin(), kept.end(),
                            [&](int i) {
                              return corners[i].pt.x >= x0 && corners[i].pt.x < x0 + 200 &&
                                     corners[i].pt.y >= y0 && corners[i].pt.y < y0 + 100;
                            }),
              10)
        << "quadrant " << q;
  }
  // Deterministic.
  EXPECT_EQ(DistributeQuadtree(corners, area, 100), kept);
}

TEST(DistributeQuadtree, PicksTheStrongestOfCoincidentCorners) {
  // Two corners at the same place cannot be separated by splitting: the node stops splitting
  // at pixel size and keeps the stronger one.
  const std::vector<cv::KeyPoint> corners = {Corner(10, 10, 1), Corner(10, 10, 9),
                                             Corner(80, 80, 3)};
  EXPECT_EQ(DistributeQuadtree(corners, cv::Rect2f(0, 0, 100, 100), 2), (std::vector<int>{1, 2}));
}

}  // namespace
}  // namespace planeloc
