#include "planeloc/prior/plane_creases.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

MapPlane MakePlane(int id, const Eigen::Vector3d& normal, double d,
                   std::vector<Eigen::Vector3d> polygon, double area) {
  MapPlane p;
  p.id = id;
  p.plane_in_map = Plane(normal, d);
  p.polygon = std::move(polygon);
  p.area = area;
  return p;
}

// z up. Ground z = 0 over [0, 10] x [0, 10]; facade x = 0 over y in [2, 8], z in [0.2, 5] (its
// outline stops 0.2 m above the ground, as a LiDAR outline does); facade y = 10 over x in
// [0, 10], z in [0, 5]; a free-standing wall x = 5 over y in [3, 7], z in [0, 3] with ground on
// both sides; a ramp 10 degrees off the ground; a small sign and a plane without outline.
PlaneMap Block() {
  const double s = std::sin(10.0 * std::numbers::pi / 180.0);
  const double c = std::cos(10.0 * std::numbers::pi / 180.0);
  auto ramp_z = [&](double y) { return s / c * (y - 5.0); };  // -sin(y - 5) + cos z = 0
  PlaneMap map;
  map.planes.push_back(
      MakePlane(3, {0, 1, 0}, -10, {{0, 10, 0}, {10, 10, 0}, {10, 10, 5}, {0, 10, 5}}, 50));
  map.planes.push_back(
      MakePlane(1, {0, 0, 1}, 0, {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}}, 100));
  map.planes.push_back(
      MakePlane(2, {1, 0, 0}, 0, {{0, 2, 0.2}, {0, 8, 0.2}, {0, 8, 5}, {0, 2, 5}}, 28.8));
  map.planes.push_back(
      MakePlane(5, {1, 0, 0}, -5, {{5, 3, 0}, {5, 7, 0}, {5, 7, 3}, {5, 3, 3}}, 12));
  map.planes.push_back(
      MakePlane(4, {0, -s, c}, s * 5.0,
                {{7, 4, ramp_z(4)}, {9, 4, ramp_z(4)}, {9, 6, ramp_z(6)}, {7, 6, ramp_z(6)}}, 8.1));
  map.planes.push_back(
      MakePlane(6, {0, 1, 0}, -1, {{1, 1, 0}, {2, 1, 0}, {2, 1, 1}, {1, 1, 1}}, 1));
  map.planes.push_back(MakePlane(7, {1, 0, 0}, -1, {}, 0));
  return map;
}

TEST(PlaneCreasesTest, CreasesOfABlockWorkedOutByHand) {
  const PlaneCreaseOptions options;  // support margin 0.5 m, min angle 30 deg, step 0.05 m
  const std::vector<PlaneCrease> creases = ComputePlaneCreases(Block(), options);
  // Expected: ground-facade x=0, ground-facade y=10, ground-wall. Not: the ramp (10 deg), the
  // two facades (facade x=0 ends at y = 8, 2 m from facade y=10), the sign (1 m^2), the plane
  // without outline.
  ASSERT_EQ(creases.size(), 3u);
  const double tolerance = options.sample_step + 1e-9;

  // Ground and facade x=0 meet on x = 0, z = 0. The facade's outline is 0.2 m above the line:
  // support within 0.5 m of its corners reaches sqrt(0.5^2 - 0.2^2) = 0.458 m beyond y = 2 and
  // y = 8.
  const double reach = std::sqrt(0.5 * 0.5 - 0.2 * 0.2);
  const PlaneCrease& a = creases[0];
  EXPECT_EQ(a.plane_a, 1);
  EXPECT_EQ(a.plane_b, 2);
  EXPECT_NEAR(a.angle_deg, 90.0, 1e-9);
  const double a_lo = std::min(a.start.y(), a.end.y()), a_hi = std::max(a.start.y(), a.end.y());
  EXPECT_NEAR(a_lo, 2.0 - reach, tolerance);
  EXPECT_NEAR(a_hi, 8.0 + reach, tolerance);
  for (const Eigen::Vector3d& end : {a.start, a.end}) {
    EXPECT_NEAR(end.x(), 0.0, 1e-9);
    EXPECT_NEAR(end.z(), 0.0, 1e-9);
  }
  EXPECT_TRUE(a.into_a.isApprox(Eigen::Vector3d(1, 0, 0)));  // the ground lies at x > 0
  EXPECT_TRUE(a.into_b.isApprox(Eigen::Vector3d(0, 0, 1)));  // the facade above the road

  // Ground and facade y=10 on y = 10, z = 0: both outlines run along it, x in [-0.5, 10.5].
  const PlaneCrease& b = creases[1];
  EXPECT_EQ(b.plane_a, 1);
  EXPECT_EQ(b.plane_b, 3);
  EXPECT_NEAR(b.Length(), 11.0, tolerance);
  EXPECT_NEAR(std::min(b.start.x(), b.end.x()), -0.5, tolerance);
  EXPECT_NEAR(b.start.y(), 10.0, 1e-9);
  EXPECT_TRUE(b.into_a.isApprox(Eigen::Vector3d(0, -1, 0)));
  EXPECT_TRUE(b.into_b.isApprox(Eigen::Vector3d(0, 0, 1)));

  // Ground and the wall on x = 5, z = 0, y in [2.5, 7.5]; the ground is on both sides: the
  // crease bounds the wall only.
  const PlaneCrease& c = creases[2];
  EXPECT_EQ(c.plane_a, 1);
  EXPECT_EQ(c.plane_b, 5);
  EXPECT_NEAR(c.Length(), 5.0, tolerance);
  EXPECT_NEAR(c.start.x(), 5.0, 1e-9);
  EXPECT_TRUE(c.into_a.isZero());
  EXPECT_TRUE(c.into_b.isApprox(Eigen::Vector3d(0, 0, 1)));
  for (int k = 0; k < 3; ++k) EXPECT_EQ(creases[k].id, k);
}

TEST(PlaneCreasesTest, GapsSplitACreaseAndShortOnesAreDropped) {
  // A facade y = 0 over x in [0, 7.2] whose bottom edge rises to z = 3 between x = 4 and
  // x = 6.5 (a gateway): the crease with the ground breaks there.
  PlaneMap map;
  map.planes.push_back(
      MakePlane(0, {0, 0, 1}, 0, {{-1, -5, 0}, {9, -5, 0}, {9, 0, 0}, {-1, 0, 0}}, 50));
  map.planes.push_back(MakePlane(1, {0, 1, 0}, 0,
                                 {{0, 0, 0},
                                  {4, 0, 0},
                                  {4, 0, 3},
                                  {6.5, 0, 3},
                                  {6.5, 0, 0},
                                  {7.2, 0, 0},
                                  {7.2, 0, 5},
                                  {0, 0, 5}},
                                 30));
  PlaneCreaseOptions options;
  std::vector<PlaneCrease> creases = ComputePlaneCreases(map, options);
  // Support x in [-0.5, 4.5] and [6.0, 7.7]; the 1.5 m gap exceeds max_gap (1 m).
  ASSERT_EQ(creases.size(), 2u);
  // Samples every 5 cm: each end can fall short by up to one step.
  const double tolerance = 2 * options.sample_step;
  const double longer = std::max(creases[0].Length(), creases[1].Length());
  const double shorter = std::min(creases[0].Length(), creases[1].Length());
  EXPECT_NEAR(longer, 5.0, tolerance);
  EXPECT_NEAR(shorter, 1.7, tolerance);
  options.min_length = 2.0;
  creases = ComputePlaneCreases(map, options);
  ASSERT_EQ(creases.size(), 1u);
  options.max_gap = 2.0;
  creases = ComputePlaneCreases(map, options);
  ASSERT_EQ(creases.size(), 1u);
  EXPECT_NEAR(creases[0].Length(), 8.2, tolerance);
}

TEST(PlaneCreasesTest, OptionsAreChecked) {
  PlaneCreaseOptions options;
  options.min_angle_deg = 0;
  EXPECT_THROW(options.Check(), OptionsError);
  options = PlaneCreaseOptions();
  options.sample_step = 0;
  EXPECT_THROW(ComputePlaneCreases(PlaneMap(), options), OptionsError);
}

}  // namespace
}  // namespace planeloc
