// Tiled LiDAR maps (issue 15): a map cut into square tiles on a grid of the two horizontal axes,
// each tile stored with an overlap band of its neighbours' points, so that `map planes` can vote
// and extract planes one tile at a time (or one tile per MPI rank) in memory set by the tile size.
//
// Tile (i, j) owns ("core") the points p with floor(p[a0] / tile_size) = i and
// floor(p[a1] / tile_size) = j, where (a0, a1) are the tiling axes; its file also holds every point
// within `overlap` metres of the core square (its "box"), so that the neighbourhoods of the core
// points near a border are complete. Each point is in exactly one core; the union of the cores is
// the map.
//
// TILES_DIR/index.json:
//   {"format":"planeloc-tiles","version":1,"tile_size":100,"overlap":5,"axes":[0,2],
//    "source":"map.pcd","points":N,
//    "tiles":[{"key":[i,j],"file":"tile_i_j.ply","points":n,"core_points":m}, ...]}
// tiles sorted by key; tile files are binary .ply (double coordinates: no precision loss for
// georeferenced maps). Written safely (util/safe_file.h); the index last, so a directory without
// index.json is an unfinished tiling.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/io/point_cloud.h"
#include "planeloc/map/map_builder.h"

namespace planeloc {

struct TilingOptions {
  double tile_size = 100.0;  // metres, side of a tile's core square
  double overlap = 5.0;      // metres, band of neighbour points stored with each tile (>= 2 r_tv)
  // Tiling axes (indices of x, y, z), the two horizontal ones. {-1, -1}: chosen from the data,
  // the two axes of largest extent (KITTI camera world, y down: x and z).
  std::array<int, 2> axes = {-1, -1};

  void Check() const;  // throws OptionsError naming the field
};

using TileKey = std::array<long long, 2>;

// The geometry of a tiling: which tile owns a point, which tiles' boxes contain it.
class TileGrid {
 public:
  // options.axes must be set (both >= 0, different).
  explicit TileGrid(const TilingOptions& options);
  const TilingOptions& options() const { return options_; }

  TileKey KeyOf(const Eigen::Vector3d& point) const;
  // Keys of the tiles whose box (core grown by the overlap) contains `point` (1 to 4).
  std::vector<TileKey> BoxKeysOf(const Eigen::Vector3d& point) const;
  bool InCore(const TileKey& key, const Eigen::Vector3d& point) const {
    return KeyOf(point) == key;
  }
  // Distance (metres, in the tiling plane) from `point` to the nearest edge of `key`'s core
  // square; negative outside the core.
  double DistanceToCoreEdge(const TileKey& key, const Eigen::Vector3d& point) const;

 private:
  TilingOptions options_;
};

// The two axes of largest extent of `points` (ascending indices); {0, 1} for fewer than 2 points.
std::array<int, 2> HorizontalAxes(const std::vector<Eigen::Vector3d>& points);

struct TileEntry {
  TileKey key = {0, 0};
  std::string file;  // relative to the tiles directory
  std::size_t points = 0;
  std::size_t core_points = 0;
};

struct TileIndex {
  TilingOptions tiling;  // axes set
  std::string source;    // the map (or sequence) the tiles were cut from
  std::size_t points = 0;
  std::vector<TileEntry> tiles;  // sorted by key
  std::filesystem::path dir;     // where index.json was read from (not written)
  // Cut from scans (`map tile --sequence`, `map build --tiles-out`): what was read and dropped
  // (MapBuildCounts::ToJson; index.json's "map_build").
  std::optional<nlohmann::json> map_build;
};

// Throws InputError naming TILES_DIR/index.json when it is missing or malformed, lists no tile,
// lists a key or a file twice, or names a file outside the folder.
TileIndex ReadTileIndex(const std::filesystem::path& dir);

// How many of a tile's points lie outside the box (core grown by the overlap) of `key`: none for
// a tile that `map tile` wrote for that key.
std::size_t CountOutsideTileBox(const TileGrid& grid, const TileKey& key,
                                const std::vector<Eigen::Vector3d>& points);
void WriteTileIndex(const std::filesystem::path& dir, const TileIndex& index);
std::string TileFileName(const TileKey& key);

// Cuts an in-memory map into tiles in `dir` (which must exist) and writes the index. Tiles
// without a core point are not written. options.axes < 0: HorizontalAxes(map).
TileIndex WriteTiles(const PointCloud& map, const TilingOptions& options,
                     const std::filesystem::path& dir, const std::string& source);

// `map build` straight into tiles: scans are accumulated per tile box (MapAccumulator each); a
// tile whose box is farther than max_range from the sensor is written out and freed, and read
// back if the trajectory returns to it, so memory follows the tiles near the sensor, not the map.
class TiledMapWriter {
 public:
  // options.axes must be set (the trajectory's horizontal axes, see HorizontalAxes).
  TiledMapWriter(MapBuildOptions build, const TilingOptions& options, std::filesystem::path dir,
                 std::string source);
  void AddScan(const std::vector<Eigen::Vector3d>& points_in_velo, const Rigid3d& world_from_velo);
  // Writes the remaining tiles and the index (core points counted from the files).
  // `frames` visited and the `missing_scans` among them go into the index's map_build counts.
  TileIndex Finish(std::size_t frames = 0, std::size_t missing_scans = 0);
  std::size_t open_tiles() const { return open_.size(); }

 private:
  void Close(TileKey key);

  MapBuildOptions build_;
  TileGrid grid_;
  std::filesystem::path dir_;
  std::string source_;
  std::map<TileKey, MapAccumulator> open_;
  std::map<TileKey, bool> written_;
  MapBuildCounts counts_;
};

}  // namespace planeloc
