#include "planeloc/map/plane_uncertainty.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace planeloc {
namespace {

// Points on the facade x = 5 (normal +x), 24 m long (z) and 8 m high (y), every 0.1 m, with white
// range noise `white` and, when `strip_sigma` > 0, one offset per 3 m strip along z: the error of a
// scan registered a few centimetres off, shared by all the points it contributed.
std::vector<Eigen::Vector3d> Facade(double white, double strip_sigma, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<double> strip(8);
  for (double& s : strip) s = strip_sigma * noise(rng);
  std::vector<Eigen::Vector3d> points;
  for (int iz = 0; iz < 240; ++iz) {
    for (int iy = 0; iy < 80; ++iy) {
      const double z = 0.1 * iz, y = 0.1 * iy;
      points.emplace_back(5.0 + strip[iz / 30] + white * noise(rng), y, z);
    }
  }
  return points;
}

std::vector<int> All(const std::vector<Eigen::Vector3d>& points) {
  std::vector<int> indices(points.size());
  for (std::size_t i = 0; i < indices.size(); ++i) indices[i] = static_cast<int>(i);
  return indices;
}

TEST(PlaneUncertaintyTest, MeasuresTheInliersGeometryAndTheirCellStructure) {
  const auto points = Facade(0.01, 0.0, 1);
  const Plane plane = Plane::Fit(points);
  const PlaneSpread spread = MeasurePlaneSpread(points, All(points), plane);
  EXPECT_EQ(spread.points, 19200);
  EXPECT_NEAR(spread.rms, 0.01, 0.0005);
  EXPECT_NEAR(std::abs(spread.major_axis.z()), 1.0, 1e-6);        // the 24 m direction
  EXPECT_NEAR(spread.extent[1], 23.9, 0.05);                      // major
  EXPECT_NEAR(spread.extent[0], 7.9, 0.05);                       // minor
  EXPECT_NEAR(spread.deviation[0], 7.9 / std::sqrt(12.0), 0.05);  // uniform over the height
  EXPECT_GE(spread.cells, 8 * 24);  // 1 m cells, each holding ~100 points
  // White noise averages within a cell: ~0.01 / sqrt(100).
  EXPECT_LT(spread.cell_spread, 0.002);
}

TEST(PlaneUncertaintyTest, CorrelatedErrorWidensTheSigmaWhereWhiteNoiseDoesNot) {
  // Same rms (about 3 cm) in both: white range noise, or 1 cm of it plus 3 cm offsets per strip.
  const auto white = Facade(0.03, 0.0, 2);
  const auto blurred = Facade(0.01, 0.03, 2);
  const PlaneSigma white_sigma =
      PlaneSigmaFromSpread(MeasurePlaneSpread(white, All(white), Plane::Fit(white)));
  const PlaneSigma blurred_sigma =
      PlaneSigmaFromSpread(MeasurePlaneSpread(blurred, All(blurred), Plane::Fit(blurred)));
  // The white plane: rms / sqrt(N) = 0.03 / sqrt(19200) = 0.2 mm, and the slab's share of its
  // 3 cm thickness; measured 6.7 mm (planeloc_map_test --gtest_filter='PlaneUncertainty*').
  EXPECT_LT(white_sigma.offset, 0.01);
  EXPECT_GT(blurred_sigma.offset, 5 * white_sigma.offset);
  EXPECT_GT(blurred_sigma.normal[1], 5 * white_sigma.normal[1]);
}

TEST(PlaneUncertaintyTest, OffsetErrorsOfStripCorrelatedPlanesFallWithinTwoSigma) {
  // 100 planes whose error is the mean of 8 strip offsets (3 cm each): the true offset error at
  // the centroid has sigma 0.03 / sqrt(8) = 1.1 cm, which rms / sqrt(N) (0.2 mm) misses entirely.
  int within_two_sigma = 0;
  for (std::uint32_t seed = 10; seed < 110; ++seed) {
    const auto points = Facade(0.01, 0.03, seed);
    const Plane plane = Plane::Fit(points);
    const PlaneSigma sigma = PlaneSigmaFromSpread(MeasurePlaneSpread(points, All(points), plane));
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const auto& p : points) centroid += p;
    centroid /= static_cast<double>(points.size());
    const double error = std::abs(centroid.x() - 5.0);  // the truth is x = 5
    within_two_sigma += error <= 2 * sigma.offset;
  }
  EXPECT_GE(within_two_sigma, 90);
}

TEST(PlaneUncertaintyTest, SamplesThatAverageCellsGiveTheSameSigmaAsThePoints) {
  // The merge across tiles knows a plane by its count, rms and per-cell averages (tile_planes.h).
  const auto points = Facade(0.01, 0.03, 3);
  const Plane plane = Plane::Fit(points);
  const PlaneSpread full = MeasurePlaneSpread(points, All(points), plane);
  std::vector<Eigen::Vector3d> samples;  // the average of each 0.5 m x 0.5 m block
  for (int bz = 0; bz < 48; ++bz) {
    for (int by = 0; by < 16; ++by) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int iz = 5 * bz; iz < 5 * bz + 5; ++iz) {
        for (int iy = 5 * by; iy < 5 * by + 5; ++iy) sum += points[iz * 80 + iy];
      }
      samples.push_back(sum / 25.0);
    }
  }
  const PlaneSpread sampled = MeasureSampledPlaneSpread(samples, full.points, full.rms, plane);
  EXPECT_NEAR(sampled.cell_spread, full.cell_spread, 0.1 * full.cell_spread);
  const PlaneSigma a = PlaneSigmaFromSpread(full);
  const PlaneSigma b = PlaneSigmaFromSpread(sampled);
  EXPECT_NEAR(b.offset, a.offset, 0.1 * a.offset);
  EXPECT_NEAR(b.normal[1], a.normal[1], 0.15 * a.normal[1]);
  EXPECT_NEAR(std::abs(b.major_axis.dot(a.major_axis)), 1.0, 1e-6);
}

TEST(PlaneUncertaintyTest, RejectsTooFewInliers) {
  const std::vector<Eigen::Vector3d> points = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_THROW(MeasurePlaneSpread(points, {0, 1}, Plane()), std::invalid_argument);
  EXPECT_THROW(MeasureSampledPlaneSpread({}, 100, 0.01, Plane()), std::invalid_argument);
}

}  // namespace
}  // namespace planeloc
