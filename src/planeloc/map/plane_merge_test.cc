#include "planeloc/map/plane_merge.h"

#include <gtest/gtest.h>

#include <numbers>

#include "planeloc/map/map_planes.h"
#include "planeloc/map/synthetic_scene_for_test.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

// A street across the corner of four 20 m tiles (borders at x = 0 and y = 0, z up): ground,
// a 36 m facade crossing the x border, a wall inside one tile, a car on the border.
PointCloud Street() {
  testing::SceneBuilder builder(0.15, 0.02, 5);
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  builder.Rectangle({-18, -6, 0}, x, 36.0, y, 14.0, true);  // ground, four tiles
  builder.Rectangle({-18, 8, 0}, x, 36.0, z, 7.0, true);    // facade y = 8 across x = 0
  builder.Rectangle({5, 2, 0}, y, 5.0, z, 4.0, true);       // wall x = 5, one tile
  builder.Box({-1, -3, 0.2}, {3, -1.2, 1.6});               // a car on both borders
  PointCloud cloud;
  cloud.points = builder.scene().points;
  return cloud;
}

MapPlanesOptions Options() {
  MapPlanesOptions options;
  options.plane_extraction.up = Eigen::Vector3d::UnitZ();
  return options;
}

// Tiles the map, extracts each tile (round-tripped through JSON as over MPI) and merges.
MergedPlanes RunTiled(const PointCloud& map, const MapPlanesOptions& options) {
  TilingOptions tiling;
  tiling.tile_size = 20.0;
  tiling.overlap = 3.0;
  tiling.axes = {0, 1};
  TempDir dir;
  const TileIndex index = WriteTiles(map, tiling, dir.path(), "street");
  const TileGrid grid(index.tiling);
  std::vector<TilePlanes> tiles;
  for (const TileEntry& entry : index.tiles) {
    const TilePlanes tile = ExtractTilePlanes(ReadPointCloud(dir.path() / entry.file), entry.key,
                                              grid, options, nullptr, {});
    tiles.push_back(
        TilePlanes::FromJson(nlohmann::json::from_cbor(nlohmann::json::to_cbor(tile.ToJson()))));
  }
  return MergeTilePlanes(tiles, options);
}

TEST(MergeTilePlanesTest, TiledEqualsUntiledAndNothingIsSplit) {
  const PointCloud map = Street();
  const MapPlanesOptions options = Options();
  const PlaneMap untiled = RunMapPlanes(map, options).extraction.plane_map;
  const MergedPlanes tiled = RunTiled(map, options);
  ASSERT_EQ(untiled.planes.size(), 3u);
  // The same planes, none split: the facade and the ground are one plane each.
  ASSERT_EQ(tiled.plane_map.planes.size(), untiled.planes.size());
  EXPECT_GE(tiled.plane_map.stats["joined_groups"].get<int>(), 2);
  for (const MapPlane& u : untiled.planes) {
    const MapPlane* match = nullptr;
    for (const MapPlane& t : tiled.plane_map.planes) {
      if (t.plane_in_map.AngleTo(u.plane_in_map) * 180.0 / std::numbers::pi < 0.5 &&
          std::abs(t.plane_in_map.SignedDistance(u.centroid)) < 0.03) {
        match = &t;
      }
    }
    ASSERT_NE(match, nullptr) << "untiled plane " << u.id << " (" << u.kind << ")";
    EXPECT_EQ(match->kind, u.kind);
    // Combined support and outline: within a few % of the untiled plane's.
    EXPECT_NEAR(match->inliers, u.inliers, 0.05 * u.inliers);
    EXPECT_NEAR(match->area, u.area, 0.08 * u.area);
    EXPECT_NEAR(match->plane_in_map.normal.dot(u.plane_in_map.normal), 1.0, 1e-4);  // same sign
  }
}

TEST(MergeTilePlanesTest, DetectedUpIsTheMajorityOfTheTiles) {
  MapPlanesOptions options = Options();
  options.plane_extraction.detect_up = true;
  const MergedPlanes tiled = RunTiled(Street(), options);
  EXPECT_TRUE(tiled.up_detected);
  EXPECT_NEAR(tiled.up.z(), 1.0, 1e-9);
  for (const MapPlane& p : tiled.plane_map.planes) {
    if (p.kind == "ground") {
      EXPECT_GT(p.plane_in_map.normal.z(), 0.99);
    }
  }
}

TEST(MergeTilePlanesTest, RejectsFailedAndUnsortedTiles) {
  std::vector<TilePlanes> tiles(1);
  tiles[0].error = "boom";
  EXPECT_THROW(MergeTilePlanes(tiles, Options()), std::invalid_argument);
}

}  // namespace
}  // namespace planeloc
