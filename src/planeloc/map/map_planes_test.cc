#include "planeloc/map/map_planes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

#include "planeloc/io/plane_map.h"
#include "planeloc/map/map_builder.h"
#include "planeloc/map/synthetic_scene_for_test.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

std::string ReadBytes(const std::filesystem::path& path) {
  std::ifstream stream(path, std::ios::binary);
  std::stringstream buffer;
  buffer << stream.rdbuf();
  return buffer.str();
}

TEST(MapPlanesTest, TwoRunsWriteIdenticalPlaneMaps) {
  PointCloud map;
  map.points = testing::SceneBuilder::StreetCorner(0.15, 0.02, 31).points;
  map.comments = {std::string(kMapBuildCommentTag) + R"({"scans":8,"empty_scans":1})"};
  MapPlanesOptions options;
  options.plane_extraction.up = Eigen::Vector3d::UnitZ();
  TempDir dir;
  const MapPlanesOutput first = RunMapPlanes(map, options);
  // What `map build` wrote into the map's header reaches planes.json (issue 37).
  EXPECT_EQ(first.extraction.plane_map.stats["map_build"]["empty_scans"], 1);
  const MapPlanesOutput second = RunMapPlanes(map, options);
  ASSERT_FALSE(first.extraction.plane_map.planes.empty());
  WritePlaneMap(dir.path() / "a.json", first.extraction.plane_map);
  WritePlaneMap(dir.path() / "b.json", second.extraction.plane_map);
  EXPECT_EQ(ReadBytes(dir.path() / "a.json"), ReadBytes(dir.path() / "b.json"));
  // The effective options are written back.
  EXPECT_EQ(first.extraction.plane_map.stats["options"]["tensor_voting.sigma"].get<double>(),
            options.tensor_voting.sigma);
  // Colours: one per point, plane points in colour, others grey / blue / dark red.
  const auto colors = PlaneColors(first);
  ASSERT_EQ(colors.size(), first.points.size());
  for (std::size_t i = 0; i < colors.size(); ++i) {
    EXPECT_TRUE((colors[i].array() >= 0.0).all() && (colors[i].array() <= 1.0).all());
  }
}

// Issue 17: a cloud ten times denser than a voxelized map (3 cm spacing, as a raw scan near the
// sensor) is voxel-filtered first and gives the planes of the voxelized map.
TEST(MapPlanesTest, DenseCloudIsVoxelFilteredToTheSamePlanes) {
  testing::SceneBuilder dense(0.03, 0.01, 5), sparse(0.1, 0.01, 5);
  for (testing::SceneBuilder* b : {&dense, &sparse}) {
    b->Rectangle({0, 0, 0}, Eigen::Vector3d::UnitX(), 12.0, Eigen::Vector3d::UnitY(), 8.0, true);
    b->Rectangle({0, 8, 0}, Eigen::Vector3d::UnitX(), 12.0, Eigen::Vector3d::UnitZ(), 5.0, true);
  }
  MapPlanesOptions options;
  options.plane_extraction.up = Eigen::Vector3d::UnitZ();
  PointCloud map;
  map.points = dense.scene().points;
  const MapPlanesOutput output = RunMapPlanes(map, options);
  EXPECT_DOUBLE_EQ(output.voxel_size, 0.1);  // sigma 0.5 / 5
  // 96 + 60 m^2 at 0.03 m = 173.6k points; one a 0.1 m voxel face on the planes is 15.6k, but
  // the ground (z = 0, 1 cm noise) lies on a voxel boundary and fills two layers: 31 329
  // measured (planeloc_map_test --gtest_filter=MapPlanesTest.Dense*).
  EXPECT_EQ(map.size(), 173'600u);
  EXPECT_GT(output.points.size(), 15'600u);
  EXPECT_LT(output.points.size(), 34'000u);
  EXPECT_EQ(output.extraction.point_plane.size(), output.points.size());
  EXPECT_EQ(output.extraction.plane_map.stats["input_points"], map.size());
  const auto& planes = output.extraction.plane_map.planes;
  ASSERT_EQ(planes.size(), 2u);
  EXPECT_EQ(planes[0].kind, "ground");
  EXPECT_EQ(planes[1].kind, "facade");
  for (std::size_t g = 0; g < 2; ++g) {
    const Plane& gt = dense.scene().gt_planes[g];
    bool matched = false;
    for (const MapPlane& p : planes) {
      matched = matched || (p.plane_in_map.AngleTo(gt) < 0.5 * std::numbers::pi / 180.0 &&
                            std::abs(gt.SignedDistance(p.centroid)) < 0.02);
    }
    EXPECT_TRUE(matched) << "GT plane " << g;
  }
  options.voxel_size = -2.0;  // any negative value = sigma / 5
  EXPECT_DOUBLE_EQ(options.EffectiveVoxelSize(), 0.1);
  options.voxel_size = std::numeric_limits<double>::infinity();
  EXPECT_THROW(RunMapPlanes(map, options), OptionsError);
}

TEST(MapPlanesTest, EmptyMapIsAnInputError) {
  EXPECT_THROW(RunMapPlanes(PointCloud(), MapPlanesOptions()), InputError);
}

}  // namespace
}  // namespace planeloc
