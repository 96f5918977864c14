#include "planeloc/map/map_tiles.h"

#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>

#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

TilingOptions XzTiling() {
  TilingOptions options;
  options.tile_size = 10.0;
  options.overlap = 1.0;
  options.axes = {0, 2};
  return options;
}

TEST(TileGridTest, KeysBoxesAndEdges) {
  const TileGrid grid(XzTiling());
  EXPECT_EQ(grid.KeyOf({5.0, 99.0, -0.5}), (TileKey{0, -1}));
  EXPECT_EQ(grid.KeyOf({-10.0, 0.0, 10.0}), (TileKey{-1, 1}));
  // Inside a core, far from its edges: one box. Near a corner: the four tiles around it.
  EXPECT_EQ(grid.BoxKeysOf({5.0, 0.0, 5.0}).size(), 1u);
  const auto corner = grid.BoxKeysOf({9.5, 0.0, 0.5});
  EXPECT_EQ(std::set<TileKey>(corner.begin(), corner.end()),
            (std::set<TileKey>{{0, -1}, {0, 0}, {1, -1}, {1, 0}}));
  EXPECT_DOUBLE_EQ(grid.DistanceToCoreEdge({0, 0}, {9.5, 0.0, 4.0}), 0.5);
  EXPECT_DOUBLE_EQ(grid.DistanceToCoreEdge({0, 0}, {11.0, 0.0, 4.0}), -1.0);
}

TEST(TileGridTest, ChecksOptions) {
  TilingOptions options = XzTiling();
  options.overlap = 10.0;
  EXPECT_THROW(options.Check(), OptionsError);
  options = XzTiling();
  options.axes = {1, 1};
  EXPECT_THROW(options.Check(), OptionsError);
  options.axes = {-1, -1};
  EXPECT_NO_THROW(options.Check());
}

TEST(HorizontalAxesTest, DropsTheAxisOfLeastExtent) {
  // A KITTI-like map: y (down) spans 20 m, x and z hundreds.
  const std::vector<Eigen::Vector3d> points = {{0, 2, 0}, {300, -18, 10}, {-50, 0, 400}};
  EXPECT_EQ(HorizontalAxes(points), (std::array<int, 2>{0, 2}));
}

TEST(WriteTilesTest, EveryPointInOneCoreAndTheIndexReadsBack) {
  PointCloud map;
  for (double x = -14.95; x < 15.0; x += 0.1) {
    for (double z = -4.95; z < 5.0; z += 0.5) map.points.emplace_back(x, 1.7, z);
  }
  TempDir dir;
  const TileIndex written = WriteTiles(map, XzTiling(), dir.path(), "map.pcd");
  const TileIndex index = ReadTileIndex(dir.path());
  ASSERT_EQ(index.tiles.size(), 8u);  // x: 4 columns of 10 m over [-15, 15], z: 2 rows
  std::size_t core = 0, stored = 0;
  const TileGrid grid(index.tiling);
  for (const TileEntry& t : index.tiles) {
    const PointCloud tile = ReadPointCloud(dir.path() / t.file);
    EXPECT_EQ(tile.size(), t.points);
    std::size_t in_core = 0;
    for (const auto& p : tile.points) {
      in_core += grid.InCore(t.key, p);
      EXPECT_GE(grid.DistanceToCoreEdge(t.key, p), -1.0 - 1e-9);  // within the overlap
    }
    EXPECT_EQ(in_core, t.core_points);
    core += t.core_points;
    stored += t.points;
  }
  EXPECT_EQ(core, map.size());
  EXPECT_GT(stored, map.size());  // the overlap bands
  EXPECT_EQ(index.points, map.size());
  EXPECT_EQ(index.tiling.axes, written.tiling.axes);
}

TEST(ReadTileIndexTest, MissingIndexIsAnInputError) {
  TempDir dir;
  EXPECT_THROW(ReadTileIndex(dir.path()), InputError);
}

// Writes the tiles of a small map and returns the folder's index.json as text.
std::string WriteSmallTiles(const std::filesystem::path& dir) {
  PointCloud map;
  for (double x = -14.95; x < 15.0; x += 0.5) {
    for (double z = -4.95; z < 5.0; z += 0.5) map.points.emplace_back(x, 1.7, z);
  }
  WriteTiles(map, XzTiling(), dir, "map.pcd");
  std::ifstream in(dir / "index.json");
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Expects ReadTileIndex to refuse the index edited by `edit`, with `needle` in the message.
void ExpectBadIndex(const std::function<void(nlohmann::json&)>& edit, const std::string& needle) {
  TempDir dir;
  nlohmann::json index = nlohmann::json::parse(WriteSmallTiles(dir.path()));
  edit(index);
  std::ofstream(dir.path() / "index.json") << index.dump(1);
  try {
    ReadTileIndex(dir.path());
    ADD_FAILURE() << "accepted an index with: " << needle;
  } catch (const InputError& error) {
    EXPECT_EQ(error.path(), (dir.path() / "index.json").string());
    EXPECT_NE(std::string(error.what()).find(needle), std::string::npos) << error.what();
  }
}

TEST(ReadTileIndexTest, RefusesAnIndexThatDoesNotDescribeItsFolder) {
  ExpectBadIndex([](nlohmann::json& d) { d["tiles"] = nlohmann::json::array(); }, "lists no tiles");
  ExpectBadIndex([](nlohmann::json& d) { d["tiles"].push_back(d["tiles"][0]); }, "listed twice");
  ExpectBadIndex(
      [](nlohmann::json& d) {
        d["tiles"][1]["file"] = d["tiles"][0]["file"];
        d["tiles"][1]["key"] = {99, 99};
      },
      "is listed for two tiles");
  for (const char* file : {"../map.ply", "/tmp/tile.ply", "sub/tile.ply", ""}) {
    ExpectBadIndex([&](nlohmann::json& d) { d["tiles"][0]["file"] = file; },
                   "not a file of the tiles folder");
  }
}

TEST(CountOutsideTileBoxTest, CountsThePointsOfAnotherTile) {
  TempDir dir;
  WriteSmallTiles(dir.path());
  const TileIndex index = ReadTileIndex(dir.path());
  const TileGrid grid(index.tiling);
  const TileEntry& first = index.tiles.front();
  const TileEntry& last = index.tiles.back();
  const PointCloud first_tile = ReadPointCloud(dir.path() / first.file);
  EXPECT_EQ(CountOutsideTileBox(grid, first.key, first_tile.points), 0u);
  // The two are 30 m apart: every point of one lies outside the other's box.
  EXPECT_EQ(CountOutsideTileBox(grid, last.key, first_tile.points), first_tile.size());
}

}  // namespace
}  // namespace planeloc
