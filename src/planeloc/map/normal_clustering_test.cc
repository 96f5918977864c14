#include "planeloc/map/normal_clustering.h"

#include <gtest/gtest.h>

#include <random>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// Three orientations with 3 degrees of noise, each appearing with both signs.
std::vector<Eigen::Vector3d> ThreeOrientations(std::vector<int>& truth) {
  const std::vector<Eigen::Vector3d> axes = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(),
                                             Eigen::Vector3d(1, 1, 0).normalized()};
  std::mt19937 rng(2);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<Eigen::Vector3d> normals;
  const int counts[3] = {3000, 1500, 700};
  for (int a = 0; a < 3; ++a) {
    for (int i = 0; i < counts[a]; ++i) {
      const double sign = i % 2 == 0 ? 1.0 : -1.0;
      normals.push_back(
          (sign * axes[a] + Eigen::Vector3d(noise(rng), noise(rng), noise(rng))).normalized());
      truth.push_back(a);
    }
  }
  return normals;
}

TEST(NormalClusteringTest, FindsKAutomaticallyAndIsSignInvariant) {
  std::vector<int> truth;
  const auto normals = ThreeOrientations(truth);
  const NormalClusters clusters = ClusterNormals(normals, {}, NormalClusteringOptions());
  ASSERT_EQ(clusters.centers.size(), 3u);
  // Ordered by weight: z first, then x, then the diagonal.
  EXPECT_GT(std::abs(clusters.centers[0].z()), 0.999);
  EXPECT_GT(std::abs(clusters.centers[1].x()), 0.999);
  EXPECT_GT(std::abs(clusters.centers[2].dot(Eigen::Vector3d(1, 1, 0).normalized())), 0.999);
  int agree = 0;
  for (std::size_t i = 0; i < normals.size(); ++i) agree += clusters.labels[i] == truth[i];
  EXPECT_GT(agree, 0.99 * normals.size());
}

TEST(NormalClusteringTest, DeterministicAndEmptyInput) {
  std::vector<int> truth;
  const auto normals = ThreeOrientations(truth);
  const auto a = ClusterNormals(normals, {}, NormalClusteringOptions());
  const auto b = ClusterNormals(normals, {}, NormalClusteringOptions());
  EXPECT_EQ(a.labels, b.labels);
  EXPECT_TRUE(ClusterNormals({}, {}, NormalClusteringOptions()).centers.empty());
  NormalClusteringOptions bad;
  bad.merge_angle_deg = 0.0;
  EXPECT_THROW(bad.Check(), OptionsError);
}

}  // namespace
}  // namespace planeloc
