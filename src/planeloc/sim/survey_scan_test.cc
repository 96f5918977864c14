#include "planeloc/sim/survey_scan.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <tuple>
#include <vector>

#include "planeloc/sim/shading.h"
#include "planeloc/sim/world.h"
#include "planeloc/util/error.h"

namespace planeloc::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

void AddWall(World& world, const Eigen::Vector3d& origin, const Eigen::Vector3d& edge_u,
             const Eigen::Vector3d& edge_v, const char* kind) {
  Quad quad;
  quad.origin = origin;
  quad.edge_u = edge_u;
  quad.edge_v = edge_v;
  quad.material = Material::kFacade;
  world.AddPlanarQuad(quad, kind);
}

// An 8 x 6 x 3 m room, every face's normal pointing inwards.
World Room(bool with_ceiling = true) {
  World world;
  const Eigen::Vector3d x(8, 0, 0), y(0, 6, 0), z(0, 0, 3);
  AddWall(world, Eigen::Vector3d::Zero(), x, y, "ground");
  if (with_ceiling) AddWall(world, z, y, x, "ceiling");
  AddWall(world, Eigen::Vector3d::Zero(), y, z, "wall");
  AddWall(world, x, z, y, "wall");
  AddWall(world, Eigen::Vector3d::Zero(), z, x, "wall");
  AddWall(world, y, x, z, "wall");
  return world;
}

SurveyScanOptions Coarse() {
  SurveyScanOptions options;
  options.angular_step_deg = 1.0;
  return options;
}

// Noise bound for points on a surface: at 6 sigma a 60 000-point scan has ~1e-4 expected
// outliers, so a change of seed or hash cannot make the tests flaky.
constexpr double kSigmas = 6.0;

// Directions of the coarse grid: 161 elevation rows (-70..90) times 360 azimuths.
constexpr std::size_t kCoarseDirections = 161 * 360;

using Key = std::tuple<std::int64_t, std::int64_t, std::int64_t>;
Key VoxelOf(const Eigen::Vector3d& p, double voxel) {
  return {static_cast<std::int64_t>(std::floor(p.x() / voxel)),
          static_cast<std::int64_t>(std::floor(p.y() / voxel)),
          static_cast<std::int64_t>(std::floor(p.z() / voxel))};
}

TEST(SurveyScanTest, ClosedRoomEveryDirectionHitsAWall) {
  const World world = Room();
  const Scene scene(world);
  const SurveyScanOptions options = Coarse();
  const std::vector<Eigen::Vector3d> points = ScanSurvey(scene, {3.7, 2.9, 1.5}, 11, options);
  // The six faces share their edges, so no ray slips out of a closed room.
  EXPECT_EQ(points.size(), kCoarseDirections);
  const double tolerance = kSigmas * options.range_noise;
  int off_surface = 0;
  for (const Eigen::Vector3d& p : points) off_surface += world.DistanceToSurface(p) > tolerance;
  EXPECT_EQ(off_surface, 0);
}

TEST(SurveyScanTest, RangeNoiseHasTheConfiguredSigmaAlongTheBeam) {
  const World world = Room();
  const Scene scene(world);
  const SurveyScanOptions options = Coarse();
  const Eigen::Vector3d station(3.7, 2.9, 1.5);
  const std::vector<Eigen::Vector3d> points = ScanSurvey(scene, station, 5, options);
  double sum = 0.0, sum_sq = 0.0;
  int n = 0;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d dir = (p - station).normalized();
    Hit hit;
    ASSERT_TRUE(scene.Intersect(station.cast<float>(), dir.cast<float>(), 100.0f, &hit));
    const double error = (p - station).norm() - hit.t;
    sum += error;
    sum_sq += error * error;
    ++n;
  }
  ASSERT_GT(n, 50000);
  const double mean = sum / n, rms = std::sqrt(sum_sq / n);
  EXPECT_LT(std::abs(mean), 0.05 * options.range_noise);  // ~12 standard errors of the mean
  EXPECT_NEAR(rms, options.range_noise, 0.03 * options.range_noise);
}

// An equiangular grid puts h / (step^2 r R^2) points per m^2 on a floor h below the scanner, so an
// annulus [r1, r2] holds one azimuth ring per elevation row between atan(h / r2) and atan(h / r1)
// below the horizon; nothing falls inside the tripod's cone.
TEST(SurveyScanTest, FloorDensityFallsWithDistanceAndTheTripodHidesTheCone) {
  const World world = Room();
  const Scene scene(world);
  const SurveyScanOptions options = Coarse();
  const Eigen::Vector3d station(4.0, 3.0, 1.5);  // 3 m from the nearest wall
  const double h = station.z();
  const std::vector<Eigen::Vector3d> points = ScanSurvey(scene, station, 3, options);
  const std::vector<double> edges = {0.6, 1.2, 2.0, 2.9};
  std::vector<int> counts(edges.size() - 1, 0);
  double closest = 1e9;
  for (const Eigen::Vector3d& p : points) {
    if (std::abs(p.z()) > kSigmas * options.range_noise) continue;  // not on the floor
    const double r = std::hypot(p.x() - station.x(), p.y() - station.y());
    closest = std::min(closest, r);
    for (std::size_t i = 0; i + 1 < edges.size(); ++i)
      counts[i] += r >= edges[i] && r < edges[i + 1];
  }
  const double cone = h / std::tan(-options.min_elevation_deg * kDeg);
  EXPECT_GT(closest, cone - 0.01);
  EXPECT_LT(closest, cone + 0.01);
  const double azimuths = 360.0 / options.angular_step_deg;
  double previous_density = 1e18;
  for (std::size_t i = 0; i + 1 < edges.size(); ++i) {
    const double rows =
        (std::atan(h / edges[i]) - std::atan(h / edges[i + 1])) / (options.angular_step_deg * kDeg);
    // Whole rows fall in or out of an annulus: one ring of slack.
    EXPECT_NEAR(counts[i], rows * azimuths, azimuths + 0.02 * rows * azimuths) << "annulus " << i;
    const double area = M_PI * (edges[i + 1] * edges[i + 1] - edges[i] * edges[i]);
    const double density = counts[i] / area;
    EXPECT_LT(density, 0.6 * previous_density) << "annulus " << i;
    previous_density = density;
  }
}

TEST(SurveyScanTest, GridIncludesBothEndsOfTheElevationRange) {
  const World world = Room();
  const Scene scene(world);
  const Eigen::Vector3d station(3.7, 2.9, 1.5);
  SurveyScanOptions options;
  options.angular_step_deg = 0.1;  // not a binary fraction: 1 / 0.1 must still give 10 steps
  options.min_elevation_deg = 10.0;
  options.max_elevation_deg = 11.0;
  EXPECT_EQ(ScanSurvey(scene, station, 1, options).size(), 11u * 3600u);
  options.angular_step_deg = 0.7;  // divides neither range: 29 rows up to 9.6, 515 azimuths
  options.min_elevation_deg = -10.0;
  options.max_elevation_deg = 10.0;
  const std::vector<Eigen::Vector3d> points = ScanSurvey(scene, station, 1, options);
  ASSERT_EQ(points.size(), 29u * 515u);
  // Lowest row first, azimuth 0 first; the last point is 9.6 degrees up at azimuth 359.8.
  const Eigen::Vector3d first = (points.front() - station).normalized();
  const Eigen::Vector3d last = (points.back() - station).normalized();
  EXPECT_NEAR(std::asin(first.z()) / kDeg, -10.0, 0.01);
  EXPECT_NEAR(std::atan2(first.y(), first.x()) / kDeg, 0.0, 0.01);
  EXPECT_NEAR(std::asin(last.z()) / kDeg, 9.6, 0.01);
  EXPECT_NEAR(std::atan2(last.y(), last.x()) / kDeg, -0.2, 0.01);
  options.min_elevation_deg = options.max_elevation_deg = 5.0;  // a single row
  EXPECT_EQ(ScanSurvey(scene, station, 1, options).size(), 515u);
}

TEST(SurveyScanTest, MissesAndHitsOutsideTheRangesGiveNoPoint) {
  World world;  // a large ground and one 8 m high wall at x = 10
  AddWall(world, {-500, -500, 0}, {1000, 0, 0}, {0, 1000, 0}, "ground");
  AddWall(world, {10, 5, 0}, {0, -10, 0}, {0, 0, 8}, "facade");
  const Scene scene(world);
  SurveyScanOptions options;
  options.angular_step_deg = 2.0;
  options.max_range = 20.0;
  const double slack = kSigmas * options.range_noise;
  const Eigen::Vector3d station(0, 0, 1.5);
  const std::vector<Eigen::Vector3d> far = ScanSurvey(scene, station, 2, options);
  ASSERT_FALSE(far.empty());
  EXPECT_LT(far.size(), 81u * 180u * 6 / 10);  // the sky and the far ground give nothing
  for (const Eigen::Vector3d& p : far) {
    EXPECT_LE((p - station).norm(), options.max_range + slack);
    EXPECT_LT(world.DistanceToSurface(p), slack);
  }
  // 0.3 m from the wall: the returns nearer than min_range are dropped, the rest kept.
  const Eigen::Vector3d close_station(9.7, 0, 1.5);
  const std::vector<Eigen::Vector3d> close = ScanSurvey(scene, close_station, 2, options);
  options.min_range = 0.0;
  const std::vector<Eigen::Vector3d> all = ScanSurvey(scene, close_station, 2, options);
  EXPECT_LT(close.size() + 100, all.size());
  for (const Eigen::Vector3d& p : close) EXPECT_GE((p - close_station).norm(), 0.4 - slack);
}

// Taking the ceiling away loses the upward returns; every other return keeps its noise exactly.
TEST(SurveyScanTest, LostReturnsDoNotShiftTheNoiseOfOthers) {
  const World closed = Room(true), open = Room(false);
  const Scene closed_scene(closed), open_scene(open);
  const Eigen::Vector3d station(3.7, 2.9, 1.5);
  const std::vector<Eigen::Vector3d> a = ScanSurvey(closed_scene, station, 9, Coarse());
  const std::vector<Eigen::Vector3d> b = ScanSurvey(open_scene, station, 9, Coarse());
  ASSERT_LT(b.size() + 1000, a.size());
  // b must be a subsequence of a (ties at the wall-ceiling edge may differ by float rounding).
  std::size_t j = 0;
  for (std::size_t i = 0; i < a.size() && j < b.size(); ++i) j += (a[i] - b[j]).norm() < 1e-5;
  EXPECT_EQ(j, b.size());
}

TEST(SurveyScanTest, SameResultWithOneAndSeveralThreads) {
  World world = Room();
  for (int i = 0; i < 12; ++i) {  // clutter so that the hints and the tree both matter
    world.AddClutterBox({1.0 + 0.5 * i, 1.0 + 0.3 * (i % 5), 0}, 0.4 * i, 0.5, 0.4, 0.8,
                        Material::kCarPaint, i);
  }
  const Scene scene(world);
  std::vector<std::vector<Eigen::Vector3d>> runs;
  for (int threads : {1, 2, 4}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    runs.push_back(ScanSurvey(scene, {3.7, 2.9, 1.5}, 21, Coarse()));
  }
  ASSERT_FALSE(runs[0].empty());
  EXPECT_TRUE(runs[0] == runs[1]);
  EXPECT_TRUE(runs[0] == runs[2]);
}

TEST(SurveyScanTest, StationsMergeInOrderAndVoxelsKeepTheirFirstPoint) {
  const World world = Room();
  const Scene scene(world);
  const std::vector<Eigen::Vector3d> stations = {{2.0, 2.0, 1.5}, {6.0, 4.0, 1.2}};
  const std::uint32_t seed = 7;
  const std::vector<Eigen::Vector3d> all = ScanSurveyStations(scene, stations, seed, 0.0, Coarse());
  std::vector<Eigen::Vector3d> expected;
  for (std::size_t i = 0; i < stations.size(); ++i) {
    const auto scan =
        ScanSurvey(scene, stations[i], HashCombine(seed, static_cast<std::uint32_t>(i)), Coarse());
    expected.insert(expected.end(), scan.begin(), scan.end());
  }
  EXPECT_TRUE(all == expected);
  EXPECT_TRUE(ScanSurveyStations(scene, stations, seed, -1.0, Coarse()) == all);

  const double voxel = 0.25;
  const std::vector<Eigen::Vector3d> thinned =
      ScanSurveyStations(scene, stations, seed, voxel, Coarse());
  EXPECT_LT(thinned.size(), all.size() / 2);
  // Exactly the first point of every occupied voxel, in merge order.
  std::set<Key> seen;
  std::size_t j = 0;
  bool in_order = true;
  for (const Eigen::Vector3d& p : all) {
    if (!seen.insert(VoxelOf(p, voxel)).second) continue;
    in_order = in_order && j < thinned.size() && thinned[j] == p;
    ++j;
  }
  EXPECT_TRUE(in_order);
  EXPECT_EQ(j, thinned.size());
  // The first station's voxels are all its own.
  const std::vector<Eigen::Vector3d> first =
      ScanSurveyStations(scene, {stations[0]}, seed, voxel, Coarse());
  ASSERT_LT(first.size(), thinned.size());
  EXPECT_TRUE(std::equal(first.begin(), first.end(), thinned.begin()));
  EXPECT_TRUE(ScanSurveyStations(scene, {}, seed, voxel, Coarse()).empty());
}

TEST(SurveyScanTest, CheckRejectsBadOptions) {
  EXPECT_NO_THROW(SurveyScanOptions{}.Check());
  const auto bad = [](auto change) {
    SurveyScanOptions options;
    change(options);
    return options;
  };
  EXPECT_THROW(bad([](auto& o) { o.angular_step_deg = 0.0; }).Check(), OptionsError);
  EXPECT_THROW(bad([](auto& o) { o.angular_step_deg = -0.25; }).Check(), OptionsError);
  EXPECT_THROW(bad([](auto& o) { o.angular_step_deg = NAN; }).Check(), OptionsError);
  EXPECT_THROW(bad([](auto& o) { o.min_range = 60.0; }).Check(), OptionsError);
  EXPECT_THROW(bad([](auto& o) { o.min_range = 70.0; }).Check(), OptionsError);
  EXPECT_THROW(bad([](auto& o) { o.min_range = -0.1; }).Check(), OptionsError);
  EXPECT_THROW(bad([](auto& o) { o.range_noise = -0.001; }).Check(), OptionsError);
  EXPECT_THROW(bad([](auto& o) { o.min_elevation_deg = 10.0, o.max_elevation_deg = 5.0; }).Check(),
               OptionsError);
  EXPECT_THROW(bad([](auto& o) { o.min_elevation_deg = -91.0; }).Check(), OptionsError);
  EXPECT_THROW(bad([](auto& o) { o.max_elevation_deg = 91.0; }).Check(), OptionsError);
  EXPECT_NO_THROW(bad([](auto& o) { o.range_noise = 0.0; }).Check());
  const World world = Room();
  const Scene scene(world);
  EXPECT_THROW(ScanSurvey(scene, {4, 3, 1.5}, 1, bad([](auto& o) { o.max_range = 0.1; })),
               OptionsError);
  EXPECT_THROW(ScanSurveyStations(scene, {{4, 3, 1.5}}, 1, NAN, Coarse()), OptionsError);
  EXPECT_THROW(ScanSurveyStations(scene, {{4, 3, 1.5}}, 1, 1e-300, Coarse()), OptionsError);
}

}  // namespace
}  // namespace planeloc::sim
