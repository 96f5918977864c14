#include "planeloc/map/map_planes.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "planeloc/io/plane_map.h"
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
  MapPlanesOptions options;
  options.plane_extraction.up = Eigen::Vector3d::UnitZ();
  TempDir dir;
  const MapPlanesOutput first = RunMapPlanes(map, options);
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
  ASSERT_EQ(colors.size(), map.size());
  for (std::size_t i = 0; i < map.size(); ++i) {
    EXPECT_TRUE((colors[i].array() >= 0.0).all() && (colors[i].array() <= 1.0).all());
  }
}

TEST(MapPlanesTest, EmptyMapIsAnInputError) {
  EXPECT_THROW(RunMapPlanes(PointCloud(), MapPlanesOptions()), InputError);
}

}  // namespace
}  // namespace planeloc
