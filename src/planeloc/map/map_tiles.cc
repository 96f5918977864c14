#include "planeloc/map/map_tiles.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <utility>

#include "planeloc/util/error.h"
#include "planeloc/util/safe_file.h"

namespace planeloc {

void TilingOptions::Check() const {
  if (!(std::isfinite(tile_size) && tile_size > 0.0)) {
    throw OptionsError("TilingOptions.tile_size must be > 0 (m)");
  }
  if (!(std::isfinite(overlap) && overlap >= 0.0 && overlap < tile_size)) {
    throw OptionsError("TilingOptions.overlap must be in [0, tile_size) (m)");
  }
  const bool automatic = axes[0] == -1 && axes[1] == -1;
  const bool valid =
      axes[0] >= 0 && axes[0] <= 2 && axes[1] >= 0 && axes[1] <= 2 && axes[0] != axes[1];
  if (!automatic && !valid) {
    throw OptionsError("TilingOptions.axes must be two different axes in 0..2 (or both -1)");
  }
}

TileGrid::TileGrid(const TilingOptions& options) : options_(options) {
  options_.Check();
  if (options_.axes[0] < 0) throw std::invalid_argument("TileGrid: tiling axes not set");
}

TileKey TileGrid::KeyOf(const Eigen::Vector3d& point) const {
  return {static_cast<long long>(std::floor(point[options_.axes[0]] / options_.tile_size)),
          static_cast<long long>(std::floor(point[options_.axes[1]] / options_.tile_size))};
}

std::vector<TileKey> TileGrid::BoxKeysOf(const Eigen::Vector3d& point) const {
  std::array<std::vector<long long>, 2> per_axis;
  for (int k = 0; k < 2; ++k) {
    const double x = point[options_.axes[k]];
    const auto lo = static_cast<long long>(std::floor((x - options_.overlap) / options_.tile_size));
    const auto hi = static_cast<long long>(std::floor((x + options_.overlap) / options_.tile_size));
    for (long long i = lo; i <= hi; ++i) per_axis[k].push_back(i);
  }
  std::vector<TileKey> keys;
  for (const long long i : per_axis[0]) {
    for (const long long j : per_axis[1]) keys.push_back({i, j});
  }
  return keys;
}

double TileGrid::DistanceToCoreEdge(const TileKey& key, const Eigen::Vector3d& point) const {
  double distance = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 2; ++k) {
    const double x = point[options_.axes[k]];
    const double lo = static_cast<double>(key[k]) * options_.tile_size;
    distance = std::min({distance, x - lo, lo + options_.tile_size - x});
  }
  return distance;
}

std::array<int, 2> HorizontalAxes(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 2) return {0, 1};
  Eigen::Vector3d lo = points.front(), hi = points.front();
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector3d extent = hi - lo;
  int vertical = 0;
  extent.minCoeff(&vertical);
  std::array<int, 2> axes{};
  for (int a = 0, k = 0; a < 3; ++a) {
    if (a != vertical) axes[k++] = a;
  }
  return axes;
}

std::string TileFileName(const TileKey& key) {
  return fmt::format("tile_{}_{}.ply", key[0], key[1]);
}

void WriteTileIndex(const std::filesystem::path& dir, const TileIndex& index) {
  nlohmann::json tiles = nlohmann::json::array();
  for (const TileEntry& t : index.tiles) {
    tiles.push_back({{"key", {t.key[0], t.key[1]}},
                     {"file", t.file},
                     {"points", t.points},
                     {"core_points", t.core_points}});
  }
  nlohmann::json doc = {{"format", "planeloc-tiles"},
                        {"version", 1},
                        {"tile_size", index.tiling.tile_size},
                        {"overlap", index.tiling.overlap},
                        {"axes", {index.tiling.axes[0], index.tiling.axes[1]}},
                        {"source", index.source},
                        {"points", index.points},
                        {"tiles", tiles}};
  if (index.map_build) doc["map_build"] = *index.map_build;
  WriteFileWhole(dir / "index.json", doc.dump(1) + "\n");
}

constexpr const char* kRecreateTiles = "re-create the tiles with `planeloc map tile`";

TileIndex ReadTileIndex(const std::filesystem::path& dir) {
  const std::filesystem::path path = dir / "index.json";
  std::ifstream in(path);
  CheckInput(in.good(), path.string(), 0, "cannot open the tile index",
             "give --tiles a folder written by `planeloc map tile` or `map build --tiles-out`");
  TileIndex index;
  index.dir = dir;
  try {
    const nlohmann::json doc = nlohmann::json::parse(in);
    CheckInput(doc.value("format", "") == "planeloc-tiles", path.string(), 0,
               "not a planeloc tile index (no \"format\": \"planeloc-tiles\")",
               "give --tiles a folder written by `planeloc map tile`");
    index.tiling.tile_size = doc.at("tile_size").get<double>();
    index.tiling.overlap = doc.at("overlap").get<double>();
    index.tiling.axes = {doc.at("axes").at(0).get<int>(), doc.at("axes").at(1).get<int>()};
    index.source = doc.value("source", "");
    index.points = doc.value("points", std::size_t{0});
    if (doc.contains("map_build") && doc["map_build"].is_object())
      index.map_build = doc["map_build"];
    for (const auto& t : doc.at("tiles")) {
      TileEntry entry;
      entry.key = {t.at("key").at(0).get<long long>(), t.at("key").at(1).get<long long>()};
      entry.file = t.at("file").get<std::string>();
      entry.points = t.value("points", std::size_t{0});
      entry.core_points = t.value("core_points", std::size_t{0});
      index.tiles.push_back(std::move(entry));
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path.string(), 0, fmt::format("malformed tile index: {}", e.what()),
                     kRecreateTiles);
  }
  try {
    index.tiling.Check();
    TileGrid grid(index.tiling);
  } catch (const std::exception& e) {
    throw InputError(path.string(), 0, fmt::format("bad tiling in the index: {}", e.what()),
                     kRecreateTiles);
  }
  CheckInput(!index.tiles.empty(), path.string(), 0, "the index lists no tiles", kRecreateTiles);
  for (const TileEntry& entry : index.tiles) {
    // A tile is a file of the folder itself: `map tile` writes plain names, and a name that leaves
    // the folder would read some other map.
    const std::filesystem::path file(entry.file);
    CheckInput(!entry.file.empty() && file.is_relative() && file.filename() == file &&
                   entry.file != "." && entry.file != "..",
               path.string(), 0,
               fmt::format("tile [{}, {}] names the file '{}', which is not a file of the tiles "
                           "folder",
                           entry.key[0], entry.key[1], entry.file),
               std::string("give each tile a plain file name in the folder of index.json; ") +
                   kRecreateTiles);
  }
  std::sort(index.tiles.begin(), index.tiles.end(),
            [](const TileEntry& a, const TileEntry& b) { return a.key < b.key; });
  for (std::size_t i = 1; i < index.tiles.size(); ++i) {
    const TileEntry& a = index.tiles[i - 1];
    const TileEntry& b = index.tiles[i];
    CheckInput(a.key != b.key, path.string(), 0,
               fmt::format("tile key [{}, {}] is listed twice ({} and {})", a.key[0], a.key[1],
                           a.file, b.file),
               kRecreateTiles);
  }
  std::set<std::string> files;
  for (const TileEntry& entry : index.tiles) {
    CheckInput(files.insert(entry.file).second, path.string(), 0,
               fmt::format("the file {} is listed for two tiles", entry.file), kRecreateTiles);
  }
  return index;
}

std::size_t CountOutsideTileBox(const TileGrid& grid, const TileKey& key,
                                const std::vector<Eigen::Vector3d>& points) {
  // The box is the core grown by the overlap; tile files hold float coordinates, hence the
  // millimetre of slack.
  const double limit = -grid.options().overlap - 1e-3;
  std::size_t outside = 0;
  for (const auto& p : points) outside += grid.DistanceToCoreEdge(key, p) < limit;
  return outside;
}

TileIndex WriteTiles(const PointCloud& map, const TilingOptions& options,
                     const std::filesystem::path& dir, const std::string& source) {
  TilingOptions tiling = options;
  tiling.Check();
  if (tiling.axes[0] < 0) tiling.axes = HorizontalAxes(map.points);
  const TileGrid grid(tiling);
  std::map<TileKey, std::vector<Eigen::Vector3d>> boxes;
  std::map<TileKey, std::size_t> cores;
  for (const auto& p : map.points) {
    ++cores[grid.KeyOf(p)];
    for (const TileKey& key : grid.BoxKeysOf(p)) boxes[key].push_back(p);
  }
  TileIndex index;
  index.tiling = tiling;
  index.source = source;
  index.points = map.size();
  for (auto& [key, points] : boxes) {
    if (cores.count(key) == 0) continue;  // only overlap: every point is in another core
    TileEntry entry;
    entry.key = key;
    entry.file = TileFileName(key);
    entry.points = points.size();
    entry.core_points = cores[key];
    PointCloud tile;
    tile.points = std::move(points);
    WritePointCloud(dir / entry.file, tile);
    index.tiles.push_back(std::move(entry));
  }
  WriteTileIndex(dir, index);
  return index;
}

TiledMapWriter::TiledMapWriter(MapBuildOptions build, const TilingOptions& options,
                               std::filesystem::path dir, std::string source)
    : build_(std::move(build)), grid_(options), dir_(std::move(dir)), source_(std::move(source)) {
  build_.Check();
  build_.show_progress = false;
}

void TiledMapWriter::AddScan(const std::vector<Eigen::Vector3d>& points_in_velo,
                             const Rigid3d& world_from_velo) {
  const double min2 = build_.min_range * build_.min_range;
  const double max2 = build_.max_range * build_.max_range;
  std::map<TileKey, std::vector<Eigen::Vector3d>> per_tile;
  ++counts_.scans;
  counts_.scan_points += points_in_velo.size();
  std::size_t kept = 0;
  for (const auto& p : points_in_velo) {
    if (!p.allFinite()) {
      ++counts_.non_finite_points;
      continue;
    }
    const double r2 = p.squaredNorm();
    if (!(r2 >= min2 && r2 <= max2)) {
      ++counts_.out_of_range_points;
      continue;
    }
    ++kept;
    const Eigen::Vector3d q = world_from_velo * p;
    for (const TileKey& key : grid_.BoxKeysOf(q)) per_tile[key].push_back(q);
  }
  counts_.empty_scans += kept == 0;
  for (auto& [key, points] : per_tile) {
    auto it = open_.find(key);
    if (it == open_.end()) {
      it = open_.try_emplace(key, build_).first;
      if (written_.count(key)) {  // the trajectory came back: continue the written tile
        it->second.AddPoints(ReadPointCloud(dir_ / TileFileName(key)).points);
      }
    }
    it->second.AddPoints(std::move(points));
  }
  // Tiles out of the sensor's reach (box farther than max_range in the tiling plane) are done
  // until the trajectory returns.
  const Eigen::Vector3d sensor = world_from_velo.translation;
  std::vector<TileKey> done;
  for (const auto& [key, accumulator] : open_) {
    const double outside = -grid_.DistanceToCoreEdge(key, sensor) - grid_.options().overlap;
    if (outside > build_.max_range) done.push_back(key);
  }
  for (const TileKey& key : done) Close(key);
}

void TiledMapWriter::Close(const TileKey key) {  // by value: erased below
  auto it = open_.find(key);
  PointCloud tile = it->second.Finish();
  open_.erase(it);
  if (!tile.empty()) WritePointCloud(dir_ / TileFileName(key), tile);
  written_[key] = !tile.empty();
}

TileIndex TiledMapWriter::Finish(std::size_t frames, std::size_t missing_scans) {
  while (!open_.empty()) Close(open_.begin()->first);
  TileIndex index;
  index.tiling = grid_.options();
  index.source = source_;
  counts_.frames = frames;
  counts_.missing_scans = missing_scans;
  for (const auto& [key, nonempty] : written_) {
    if (!nonempty) continue;
    TileEntry entry;
    entry.key = key;
    entry.file = TileFileName(key);
    const PointCloud tile = ReadPointCloud(dir_ / entry.file);  // one tile at a time
    entry.points = tile.size();
    for (const auto& p : tile.points) entry.core_points += grid_.InCore(key, p);
    index.points += entry.core_points;
    if (entry.core_points == 0) {
      std::filesystem::remove(dir_ / entry.file);
      continue;
    }
    index.tiles.push_back(std::move(entry));
  }
  CheckInput(!index.tiles.empty(), source_, 0,
             "the map is empty: no scan point lies within the range limits",
             "check --min-range / --max-range (metres)");
  counts_.map_points = index.points;
  index.map_build = counts_.ToJson();
  if (counts_.empty_scans > 0 || counts_.non_finite_points > 0) {
    spdlog::warn(
        "map tile: {} of the {} scans gave no point (empty, all NaN/Inf, or all beyond "
        "--min-range/--max-range); {} NaN/Inf points dropped (a damaged scan file)",
        counts_.empty_scans, counts_.scans, counts_.non_finite_points);
  }
  WriteTileIndex(dir_, index);
  return index;
}

}  // namespace planeloc
