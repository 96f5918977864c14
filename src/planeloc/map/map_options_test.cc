#include "planeloc/map/map_options.h"

#include <gtest/gtest.h>

#include <fstream>

#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

TEST(MapOptionsTest, LoadsNestedKeysAndReportsUnknownOnes) {
  TempDir dir;
  const auto path = dir.path() / "o.yaml";
  std::ofstream(path) << "tensor_voting:\n  sigma: 0.8\n  stick_passes: 1\n"
                         "plane_extraction:\n  up: [0, 0, 1]\n  min_area: 12\n  colour: red\n"
                         "  clustering:\n    max_clusters: 7\n";
  MapPlanesOptions options;
  const auto unknown = LoadMapPlanesOptions(path, options);
  EXPECT_DOUBLE_EQ(options.tensor_voting.sigma, 0.8);
  EXPECT_EQ(options.tensor_voting.stick_passes, 1);
  EXPECT_EQ(options.plane_extraction.up, Eigen::Vector3d(0, 0, 1));
  EXPECT_DOUBLE_EQ(options.plane_extraction.min_area, 12.0);
  EXPECT_EQ(options.plane_extraction.clustering.max_clusters, 7);
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_EQ(unknown[0], "plane_extraction.colour");
  const nlohmann::json json = MapOptionsToJson(options);
  EXPECT_DOUBLE_EQ(json["tensor_voting.sigma"].get<double>(), 0.8);
  EXPECT_EQ(json["plane_extraction.up"][2].get<double>(), 1.0);
}

TEST(MapOptionsTest, WrongTypeNamesFileAndLine) {
  TempDir dir;
  const auto path = dir.path() / "bad.yaml";
  std::ofstream(path) << "tensor_voting:\n  sigma: wide\n";
  MapPlanesOptions options;
  try {
    LoadMapPlanesOptions(path, options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_NE(e.problem().find("tensor_voting.sigma"), std::string::npos);
  }
  EXPECT_THROW(LoadMapPlanesOptions(dir.path() / "missing.yaml", options), InputError);
}

TEST(MapOptionsTest, ValueOutOfRangeNamesKeyAndLineNotTheStruct) {
  TempDir dir;
  const auto path = dir.path() / "range.yaml";
  std::ofstream(path) << "voxel_size: 0.1\ntensor_voting:\n  sigma: -1\n";
  MapPlanesOptions options;
  try {
    LoadMapPlanesOptions(path, options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.path(), path.string());
    EXPECT_EQ(e.line(), 3);
    EXPECT_NE(e.problem().find("tensor_voting.sigma"), std::string::npos) << e.problem();
    EXPECT_EQ(e.problem().find("Options."), std::string::npos) << e.problem();
  }
  std::ofstream(path) << "voxel_size: 0.1\ncoarse_below_plane_fraction: 1.5\n";
  try {
    MapPlanesOptions defaults;
    LoadMapPlanesOptions(path, defaults);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_NE(e.problem().find("coarse_below_plane_fraction"), std::string::npos) << e.problem();
  }
}

}  // namespace
}  // namespace planeloc
