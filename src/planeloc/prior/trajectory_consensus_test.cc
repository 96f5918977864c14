#include "planeloc/prior/trajectory_consensus.h"

#include <gtest/gtest.h>

#include <random>

namespace planeloc {
namespace {

ConsensusWitness Witness(std::size_t index, const Eigen::Vector3d& normal, double offset,
                         int points = 10) {
  std::mt19937 rng(static_cast<unsigned>(index) + 1);
  std::normal_distribution<double> noise(0.0, 0.02);
  ConsensusWitness w;
  w.plane_index = index;
  w.normal = normal;
  for (int i = 0; i < points; ++i) w.distances.push_back(offset + noise(rng));
  return w;
}

TEST(TrajectoryConsensusTest, RobustMedianIgnoresAnOutlier) {
  std::vector<double> values = {0.10, 0.11, 0.09, 0.10, 5.0};
  const RobustLocation location = RobustMedian(values);
  EXPECT_DOUBLE_EQ(location.median, 0.10);
  EXPECT_LT(location.standard_error, 0.02);
}

// Facades on both sides of a street have opposite normals: a trajectory 0.3 m off along +x puts
// the points of the one facing +x at +0.3 and of the one facing -x at -0.3. Both support e.
TEST(TrajectoryConsensusTest, FacadesFacingEachOtherAgreeOnOneOffset) {
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  const TrajectoryConsensus consensus = FindTrajectoryConsensus(
      {Witness(0, x, 0.3), Witness(1, -x, -0.3), Witness(2, x, 0.3)}, ConsensusRule());
  EXPECT_NEAR(consensus.offset.x(), 0.3, 0.02);
  EXPECT_NEAR(consensus.offset.tail<2>().norm(), 0.0, 1e-12);
  EXPECT_EQ(consensus.supporters.size(), 3u);
  // A facade of another direction neither supports nor opposes; too few points do not vote.
  const TrajectoryConsensus fewer = FindTrajectoryConsensus(
      {Witness(0, x, 0.3), Witness(1, -x, -0.3), Witness(2, x, 0.3, /*points=*/2),
       Witness(3, Eigen::Vector3d::UnitZ(), 0.3)},
      ConsensusRule());
  EXPECT_TRUE(fewer.offset.isZero());
}

}  // namespace
}  // namespace planeloc
