#include "planeloc/prior/registration_voting.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <random>

namespace planeloc {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
const Eigen::Vector3d kUp(0, -1, 0);  // KITTI camera world: y down

ShiftGrid Grid(double half_range, double cell) {
  ShiftGrid grid;
  grid.axis[0] = Eigen::Vector3d::UnitX();
  grid.axis[1] = Eigen::Vector3d::UnitZ();
  grid.half_range[0] = grid.half_range[1] = half_range;
  grid.cell = cell;
  grid.cells[0] = grid.cells[1] = static_cast<int>(std::ceil(2 * half_range / cell)) + 1;
  return grid;
}

std::vector<double> Headings(double range_deg, double step_deg) {
  std::vector<double> headings;
  for (double h = -range_deg; h <= range_deg + 1e-9; h += step_deg) headings.push_back(h * kDegree);
  return headings;
}

TEST(RegistrationVotingTest, VerticalShiftIsTheFullestBinDespiteOutliers) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::uniform_real_distribution<double> anywhere(-1.0, 1.0);
  std::vector<double> shifts;
  for (int i = 0; i < 200; ++i) shifts.push_back(0.31 + noise(rng));
  for (int i = 0; i < 150; ++i) shifts.push_back(anywhere(rng));  // other surfaces, spread out
  // 5 cm bins: the answer is a bin centre, within half a bin (+ the noise's mean error).
  EXPECT_NEAR(VoteVerticalShift(shifts, 1.0, 0.05), 0.31, 0.03);
  EXPECT_EQ(VoteVerticalShift({}, 1.0, 0.05), 0.0);
  EXPECT_EQ(VoteVerticalShift({5.0, -7.0}, 1.0, 0.05), 0.0);  // out of range: no vote
}

// Two walls at a corner seen from a world frame that is off by a known heading and shift: the
// best peak is that correction (up to the grid's resolution).
TEST(RegistrationVotingTest, CornerWallsVoteForTheTrueHeadingAndShift) {
  // Map: a facade x = 6 (z in [0, 40]) and a wall across the road z = 30 (x in [-5, 6]).
  const Plane facade_plane(Eigen::Vector3d(1, 0, 0), -6.0);
  const Plane wall_plane(Eigen::Vector3d(0, 0, 1), -30.0);
  const std::vector<HoughFacade> facades = {
      MakeHoughFacade(facade_plane, {{6, -6, 0}, {6, 1.65, 0}, {6, 1.65, 40}, {6, -6, 40}}, kUp),
      MakeHoughFacade(wall_plane, {{-5, -6, 30}, {6, -6, 30}, {6, 1.65, 30}, {-5, 1.65, 30}}, kUp)};
  // The correction map_from_world: p_map = R (p - c) + c + delta.
  const Eigen::Vector3d pivot(0, 0, 5);
  const double heading = 2.0 * kDegree;
  const Eigen::Vector3d delta(0.7, 0.0, -1.2);
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(heading, kUp).toRotationMatrix();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> height(-5.0, 1.0), along_facade(5.0, 28.0),
      across(-4.0, 5.5);
  std::vector<Eigen::Vector3d> world_points;
  for (int i = 0; i < 150; ++i) {
    const Eigen::Vector3d on_facade(6.0, height(rng), along_facade(rng));
    const Eigen::Vector3d on_wall(across(rng), height(rng), 30.0);
    for (const Eigen::Vector3d& q : {on_facade, on_wall}) {
      world_points.push_back(rotation.transpose() * (q - pivot - delta) + pivot);
    }
  }
  const std::vector<HeadingShiftPeak> peaks = VoteHeadingAndShift(
      world_points, pivot, kUp, facades, Headings(5.0, 1.0), Grid(4.0, 0.25), HoughOptions());
  ASSERT_FALSE(peaks.empty());
  const HeadingShiftPeak& best = peaks.front();
  // The 3x3 box filter makes a plateau one cell (0.25 m) wide around the true shift, and a 1 deg
  // heading step moves the facade's far points by 0.4 m: the grid is only as fine as that (the
  // Gauss-Newton refinement does the rest). Measured: best 912 votes at 2 deg, (1.0, -1.0).
  EXPECT_NEAR(best.heading, heading, 1.0 * kDegree + 1e-9);
  EXPECT_NEAR(best.shift_xy.x(), delta.x(), 0.375);
  EXPECT_NEAR(best.shift_xy.z(), delta.z(), 0.375);
  EXPECT_EQ(best.shift_xy.y(), 0.0);  // horizontal only
  EXPECT_GE(best.votes, 300);         // every point voted near the true cell
  // A heading 7 deg off puts the two walls' votes in no common cell: its best is far below.
  double votes_7_deg_off = 0;
  for (const HeadingShiftPeak& peak : peaks) {
    if (std::abs(peak.heading - (heading - 7.0 * kDegree)) < 1e-6) {
      votes_7_deg_off = std::max(votes_7_deg_off, peak.votes);
    }
  }
  std::cout << "best " << best.votes << ", 7 deg off " << votes_7_deg_off << "\n";
  EXPECT_LT(votes_7_deg_off, 0.7 * best.votes);
  // Peaks are ordered best first.
  for (std::size_t k = 1; k < peaks.size(); ++k) EXPECT_LE(peaks[k].votes, peaks[k - 1].votes);
}

// A point on the infinite extension of a facade, far beyond its outline, must not vote: only
// shifts that keep it on the wall count (the street behind a facade is not the facade).
TEST(RegistrationVotingTest, VotesAreClippedToTheFacadeExtent) {
  const Plane plane(Eigen::Vector3d(1, 0, 0), -6.0);
  const HoughFacade bounded =
      MakeHoughFacade(plane, {{6, -6, 0}, {6, 1.65, 0}, {6, 1.65, 10}, {6, -6, 10}}, kUp);
  const HoughFacade unbounded = MakeHoughFacade(plane, {}, kUp);
  EXPECT_NEAR(bounded.along_hi - bounded.along_lo, 10.0, 1e-9);
  // 25 m beyond the facade's end along it, 0.5 m off its plane.
  const std::vector<Eigen::Vector3d> points(20, Eigen::Vector3d(5.5, -2.0, 35.0));
  const Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
  EXPECT_TRUE(
      VoteHeadingAndShift(points, pivot, kUp, {bounded}, {0.0}, Grid(4.0, 0.25), HoughOptions())
          .empty());
  const std::vector<HeadingShiftPeak> peaks =
      VoteHeadingAndShift(points, pivot, kUp, {unbounded}, {0.0}, Grid(4.0, 0.25), HoughOptions());
  ASSERT_FALSE(peaks.empty());
  // The unbounded facade's votes lie on the line x-shift = +0.5 (any z-shift).
  EXPECT_NEAR(peaks.front().shift_xy.x(), 0.5, 0.13);
  // Above the facade's top (1 m over its outline, beyond the 0.5 m height margin): no vote.
  const std::vector<Eigen::Vector3d> high(20, Eigen::Vector3d(5.5, -7.5, 5.0));
  EXPECT_TRUE(
      VoteHeadingAndShift(high, pivot, kUp, {bounded}, {0.0}, Grid(4.0, 0.25), HoughOptions())
          .empty());
}

}  // namespace
}  // namespace planeloc
