#include "planeloc/prior/cloud_surfaces.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// A 0.2 m grid (the depth prior's voxel) on the plane z = 0.3 x + 1 around the origin, with
// `noise` metres of Gaussian scatter along z.
std::vector<Eigen::Vector3d> SlopedGrid(double noise, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> scatter(0.0, noise);
  std::vector<Eigen::Vector3d> points;
  for (double x = -3; x <= 3; x += 0.2) {
    for (double y = -3; y <= 3; y += 0.2) points.emplace_back(x, y, 0.3 * x + 1 + scatter(rng));
  }
  return points;
}

const Eigen::Vector3d kSlopeNormal = Eigen::Vector3d(-0.3, 0, 1).normalized();

TEST(CloudSurfacesTest, FitsTheLocalPlaneOfAFlatPatch) {
  const CloudSurfaces surfaces(MapCloudIndex(SlopedGrid(0.01)), CloudSurfaceOptions{});
  const std::optional<CloudSurface> surface = surfaces.Fit(Eigen::Vector3d(0.5, -0.4, 1.3));
  ASSERT_TRUE(surface);
  // 1 - cos(1 deg) = 1.5e-4.
  EXPECT_GT(std::abs(surface->plane_in_map.normal.dot(kSlopeNormal)), 1 - 1.5e-4);
  // On the plane z = 0.3 x + 1 at x = 0.5: z = 1.15.
  EXPECT_NEAR(surface->plane_in_map.SignedDistance(Eigen::Vector3d(0.5, -0.4, 1.15)), 0, 0.01);
  // The scatter along z is 0.01 m, along the normal 0.01 cos(16.7 deg) = 0.0096 m.
  EXPECT_NEAR(surface->thickness, 0.0096, 0.004);
  // 0.6 m radius on a 0.2 m grid: about pi 0.36 / 0.04 / cos(16.7 deg) = 29 points.
  EXPECT_GT(surface->num_points, 20);
  EXPECT_LT(surface->num_points, 40);
}

TEST(CloudSurfacesTest, FoliageAPoleAndEmptySpaceHaveNoSurface) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> inside(-0.5, 0.5);
  std::vector<Eigen::Vector3d> cloud;
  for (int i = 0; i < 400; ++i)
    cloud.emplace_back(inside(rng), inside(rng), inside(rng));        // a bush
  for (double z = 0; z < 4; z += 0.05) cloud.emplace_back(10, 0, z);  // a pole, one ring deep
  const CloudSurfaces surfaces(MapCloudIndex(cloud), CloudSurfaceOptions{});
  EXPECT_FALSE(surfaces.Fit(Eigen::Vector3d(0, 0, 0)));
  EXPECT_FALSE(surfaces.Fit(Eigen::Vector3d(10, 0, 2)));
  EXPECT_FALSE(surfaces.Fit(Eigen::Vector3d(20, 0, 0)));
  // Without the spread test the pole's points do give a (meaningless) plane: the test is what
  // rejects it.
  CloudSurfaceOptions no_spread;
  no_spread.min_spread = 0;
  EXPECT_TRUE(CloudSurfaces(MapCloudIndex(cloud), no_spread).Fit(Eigen::Vector3d(10, 0, 2)));
}

PointEstimate Estimate(const Eigen::Vector3d& p) {
  PointEstimate estimate;
  estimate.point_in_map = p;
  estimate.covariance = Eigen::Vector3d(1e-4, 1e-4, 9e-4).asDiagonal();  // 1, 1, 3 cm
  return estimate;
}

// Points 3 cm off the patch pass the gate, 0.3 m off do not (max_distance 0.15); a point the plane
// map already took keeps its plane; the patches are new planes after the problem's own.
TEST(CloudSurfacesTest, AssociatesThePointsNearAPatch) {
  const CloudSurfaces surfaces(MapCloudIndex(SlopedGrid(0.0)), CloudSurfaceOptions{});
  WindowProblem problem;
  WindowPointEstimates estimates;
  problem.planes.push_back(WindowPlane{7, Plane(Eigen::Vector3d::UnitX(), 0)});
  for (int i = 0; i < 12; ++i) {
    const double x = -2 + 0.3 * i;
    const double off = i < 8 ? 0.03 : 0.3;  // metres along z
    problem.points.push_back(
        WindowPoint{i, Eigen::Vector3d(x, 0.1, 0.3 * x + 1 + off), std::nullopt, 0});
    estimates.push_back(Estimate(problem.points.back().point_in_world));
  }
  problem.points.push_back(WindowPoint{12, Eigen::Vector3d(0, 0, 1), 7, 0.02});
  estimates.push_back(Estimate(problem.points.back().point_in_world));
  problem.points.push_back(
      WindowPoint{13, Eigen::Vector3d(0, 0.5, 1), std::nullopt, 0});  // no stereo: no estimate
  estimates.push_back(std::nullopt);

  PlaneAssociationOptions gate;
  gate.min_associations = 8;
  EXPECT_EQ(surfaces.Associate(problem, estimates, gate), 8);
  ASSERT_EQ(problem.planes.size(), 9u);
  for (int i = 0; i < 8; ++i) {
    ASSERT_TRUE(problem.points[i].plane_id) << i;
    EXPECT_EQ(*problem.points[i].plane_id, 8 + i);
    // n^T Sigma n = (0.3^2 1e-4 + 9e-4) / 1.09 = 8.34e-4 on an exact grid (thickness 0), with
    // the map's 0.05 m: sigma = sqrt(8.34e-4 + 2.5e-3) = 0.0577 m.
    EXPECT_NEAR(problem.points[i].plane_sigma, 0.0577, 5e-4) << i;
  }
  for (int i = 8; i < 12; ++i) EXPECT_FALSE(problem.points[i].plane_id) << i;
  EXPECT_EQ(problem.points[12].plane_id, 7);
  EXPECT_DOUBLE_EQ(problem.points[12].plane_sigma, 0.02);
  EXPECT_FALSE(problem.points[13].plane_id);
  const WindowPlane& patch = problem.planes[1];
  EXPECT_EQ(patch.id, 8);
  EXPECT_GT(std::abs(patch.plane_in_world.normal.dot(kSlopeNormal)), 1 - 1e-9);
  EXPECT_EQ(patch.offset_sigma, 0);  // held fixed
}

TEST(CloudSurfacesTest, TooFewPointsOnPatchesGiveNone) {
  const CloudSurfaces surfaces(MapCloudIndex(SlopedGrid(0.0)), CloudSurfaceOptions{});
  WindowProblem problem;
  WindowPointEstimates estimates;
  for (int i = 0; i < 5; ++i) {
    problem.points.push_back(
        WindowPoint{i, Eigen::Vector3d(0.2 * i, 0, 0.06 * i + 1), std::nullopt, 0});
    estimates.push_back(Estimate(problem.points.back().point_in_world));
  }
  PlaneAssociationOptions gate;
  gate.min_associations = 6;
  EXPECT_EQ(surfaces.Associate(problem, estimates, gate), 5);  // passed the gate, but not used
  EXPECT_TRUE(problem.planes.empty());
  for (const WindowPoint& p : problem.points) EXPECT_FALSE(p.plane_id);
}

TEST(CloudSurfacesTest, RejectsBadOptions) {
  const MapCloudIndex cloud(SlopedGrid(0.0));
  CloudSurfaceOptions options;
  options.radius = 0;
  EXPECT_THROW(CloudSurfaces(cloud, options), OptionsError);
  options = {};
  options.max_thickness = -1;
  EXPECT_THROW(CloudSurfaces(cloud, options), OptionsError);
  options = {};
  options.min_spread = 1;
  EXPECT_THROW(CloudSurfaces(cloud, options), OptionsError);
}

}  // namespace
}  // namespace planeloc
