#include "map_tiles_cli.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "flags.h"
#include "mpi_world.h"
#include "plane_map_eval_log.h"
#include "planeloc/io/kitti_sequence.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/io/point_cloud.h"
#include "planeloc/io/trajectory.h"
#include "planeloc/map/map_planes.h"
#include "planeloc/map/plane_map_eval.h"
#include "planeloc/map/plane_merge.h"
#include "planeloc/map/tile_planes.h"
#include "planeloc/util/error.h"
#include "planeloc/util/safe_file.h"

namespace planeloc::cli {
namespace {

void CheckTilingFlags(const TilingOptions& t) {
  CheckFlag(std::isfinite(t.tile_size) && t.tile_size > 0.0, "--tile-size", t.tile_size,
            "a tile side in metres, > 0", "e.g. --tile-size 100");
  CheckFlag(AtLeast(t.overlap, 0.0) && t.overlap < t.tile_size, "--overlap", t.overlap,
            fmt::format("a band in metres, >= 0 and below --tile-size ({}); at least twice the "
                        "tensor-voting radius (0.75 m by default)",
                        t.tile_size),
            "e.g. --overlap 5");
}

void MakeTilesFolder(const std::string& out) {
  std::error_code error;
  std::filesystem::create_directories(out, error);
  CheckInput(!error && std::filesystem::is_directory(out), out, 0,
             fmt::format("cannot create the tiles folder: {}",
                         error ? error.message() : "a file of that name exists"),
             "give --out a new or existing folder");
}

// The vertical axis of the map frame: the one the first scan's Velodyne z axis is closest to.
std::array<int, 2> AxesFromSensor(const Rigid3d& world_from_velo) {
  const Eigen::Vector3d up = world_from_velo.rotation * Eigen::Vector3d::UnitZ();
  int vertical = 0;
  up.cwiseAbs().maxCoeff(&vertical);
  std::array<int, 2> axes{};
  for (int a = 0, k = 0; a < 3; ++a) {
    if (a != vertical) axes[k++] = a;
  }
  return axes;
}

TileIndex TileSequence(const TileArgs& args) {
  const KittiSequence sequence = KittiSequence::Open(args.sequence);
  const Trajectory poses = ReadKittiTrajectory(args.poses);
  CheckInput(poses.size() == sequence.size(), args.poses, 0,
             fmt::format("{} poses for the {} frames of {}", poses.size(), sequence.size(),
                         sequence.folder().string()),
             "give --poses the pose file of this sequence (one world_from_cam per frame)");
  const Rigid3d& cam_from_velo = sequence.RequireCamFromVelo();
  CheckInput(!poses.world_from_cam.empty(), args.poses, 0, "no poses",
             "give --poses the pose file of this sequence (one world_from_cam per frame)");
  TilingOptions tiling = args.tiling;
  if (tiling.axes[0] < 0) {
    tiling.axes = AxesFromSensor(poses.world_from_cam.front() * cam_from_velo);
  }
  TiledMapWriter writer(args.build, tiling, args.out, args.sequence);
  std::size_t most_open = 0;
  const MapBuildCounts visited =
      ForEachScan(args.build, sequence, poses,
                  [&](const std::vector<Eigen::Vector3d>& points, const Rigid3d& world_from_velo) {
                    writer.AddScan(points, world_from_velo);
                    most_open = std::max(most_open, writer.open_tiles());
                  });
  spdlog::info("map tile: at most {} tiles open at once while streaming the scans", most_open);
  return writer.Finish(visited.frames, visited.missing_scans);
}

}  // namespace

int RunTile(const TileArgs& args) {
  CheckTilingFlags(args.tiling);
  CheckFlag(args.map.empty() != args.sequence.empty(), "--map/--sequence",
            args.map.empty() ? "(neither)" : "(both)", "a map file or a sequence, not both",
            "e.g. --map map.pcd, or --sequence SEQ --poses POSES");
  CheckFlag(args.sequence.empty() || !args.poses.empty(), "--poses", "(missing)",
            "the poses of --sequence", "e.g. --poses poses/00.txt");
  MakeTilesFolder(args.out);
  TileIndex index;
  if (!args.map.empty()) {
    index = WriteTiles(ReadPointCloud(args.map), args.tiling, args.out,
                       std::filesystem::absolute(args.map).lexically_normal().string());
  } else {
    index = TileSequence(args);
  }
  std::size_t largest = 0;
  for (const TileEntry& t : index.tiles) largest = std::max(largest, t.points);
  spdlog::info(
      "map tile: {} points -> {} tiles of {} m (+{} m overlap, axes {}) in {}, largest "
      "{} points",
      index.points, index.tiles.size(), index.tiling.tile_size, index.tiling.overlap,
      fmt::join(index.tiling.axes, ","), args.out, largest);
  return 0;
}

namespace {

TilePlanes ProcessTile(const TileIndex& index, const TileEntry& entry,
                       const MapPlanesOptions& options, const PlaneMap* gt,
                       const PlaneMapEvalOptions& eval_options) {
  const std::filesystem::path path = index.dir / entry.file;
  try {
    PointCloudReadOptions read_options;
    read_options.voxel_size = options.EffectiveVoxelSize();
    const PointCloud tile = ReadPointCloud(path, read_options);
    const TileGrid grid(index.tiling);
    const std::size_t outside = CountOutsideTileBox(grid, entry.key, tile.points);
    CheckInput(outside == 0, path.string(), 0,
               fmt::format("{} of its {} points lie outside the box of tile [{}, {}], the key "
                           "index.json gives it (the index and the tiles do not belong together)",
                           outside, tile.size(), entry.key[0], entry.key[1]),
               "re-create the tiles with `planeloc map tile`");
    TilePlanes result = ExtractTilePlanes(tile, entry.key, grid, options, gt, eval_options);
    result.file = path.string();
    return result;
  } catch (const std::exception& e) {  // reported by rank 0 with the tile
    TilePlanes failed;
    failed.key = entry.key;
    failed.file = path.string();
    failed.error = e.what();
    return failed;
  }
}

// Rank 0: the tiles' results in key order; throws InputError naming every missing tile.
std::vector<TilePlanes> CollectTiles(const TileIndex& index,
                                     const std::vector<std::string>& gathered) {
  std::map<TileKey, TilePlanes> by_key;
  for (const std::string& blob : gathered) {
    for (const auto& json : nlohmann::json::from_cbor(blob)) {
      TilePlanes tile = TilePlanes::FromJson(json);
      by_key[tile.key] = std::move(tile);
    }
  }
  std::vector<TilePlanes> tiles;
  std::vector<std::string> missing;
  for (const TileEntry& entry : index.tiles) {
    auto it = by_key.find(entry.key);
    if (it == by_key.end()) {
      missing.push_back(fmt::format("{} (no result)", entry.file));
    } else if (!it->second.error.empty()) {
      missing.push_back(fmt::format("{} ({})", entry.file, it->second.error));
    } else {
      tiles.push_back(std::move(it->second));
    }
  }
  CheckInput(missing.empty(), (index.dir / "index.json").string(), 0,
             fmt::format("{} of {} tiles failed, no plane map written: {}", missing.size(),
                         index.tiles.size(), fmt::join(missing, "; ")),
             "fix or re-create the failed tiles (planeloc map tile) and run again");
  return tiles;
}

int MergeAndWrite(const TiledPlanesArgs& args, const MapPlanesOptions& options,
                  const TileIndex& index, const std::vector<TilePlanes>& tiles,
                  const std::optional<PlaneMap>& gt, const PlaneMapEvalOptions& eval_options) {
  MergedPlanes merged = MergeTilePlanes(tiles, options);
  PlaneMap& planes = merged.plane_map;
  planes.stats["options"] = MapOptionsToJson(options);
  planes.stats["tiling"] = {{"tile_size", index.tiling.tile_size},
                            {"overlap", index.tiling.overlap},
                            {"axes", index.tiling.axes},
                            {"tiles_dir", args.tiles}};
  planes.stats["input_points"] = index.points;
  if (index.map_build) planes.stats["map_build"] = *index.map_build;
  planes.stats["voxel_size"] = options.EffectiveVoxelSize();
  planes.frame.name = args.frame;
  planes.frame.map_file = std::filesystem::absolute(args.tiles).lexically_normal().string();
  planes.frame.up = merged.up;
  planes.frame.up_source = merged.up_detected ? "detected" : "given";
  spdlog::info(
      "map planes: {} tiles merged into {} planes ({} of them joined from pieces), up = "
      "[{:.3f}, {:.3f}, {:.3f}] ({})",
      tiles.size(), planes.planes.size(), planes.stats["joined_groups"].get<int>(), merged.up.x(),
      merged.up.y(), merged.up.z(), planes.frame.up_source);
  RequirePlanarStructure(planes, args.tiles, index.points, options);
  if (gt) {
    const PlaneMapEvaluation evaluation =
        FinishPlaneMapEvaluation(MergeTileTallies(tiles, merged), planes, *gt, eval_options);
    LogPlaneMapEvaluation(args.gt, evaluation, eval_options);
    planes.stats["gt_evaluation"] = evaluation.ToJson();
  }
  WritePlaneMap(args.out, planes);
  return 0;
}

int RunTiledPlanesOnRanks(const TiledPlanesArgs& args, const MapPlanesOptions& options,
                          const MpiWorld& world) {
  CheckOutputPaths({{"--out", args.out}}, {{"--gt", args.gt}});
  const TileIndex index = ReadTileIndex(args.tiles);
  std::optional<PlaneMap> gt;
  if (!args.gt.empty()) gt = ReadPlaneMap(args.gt);
  PlaneMapEvalOptions eval_options;
  const double voxel = options.EffectiveVoxelSize();
  eval_options.point_area = voxel > 0.0 ? voxel * voxel : 0.01;
  eval_options.min_visible_area = args.gt_min_area;
  if (args.gt_all_kinds) eval_options.kinds = {"ground", "facade", "other"};
  nlohmann::json mine = nlohmann::json::array();
  for (std::size_t i = 0; i < index.tiles.size(); ++i) {
    if (static_cast<int>(i % world.size()) != world.rank()) continue;
    const TileEntry& entry = index.tiles[i];
    const TilePlanes tile = ProcessTile(index, entry, options, gt ? &*gt : nullptr, eval_options);
    if (tile.error.empty()) {
      spdlog::info("map planes: tile {}/{} {} (rank {}): {} points, {} planes, {:.1f} s", i + 1,
                   index.tiles.size(), entry.file, world.rank(), tile.points, tile.pieces.size(),
                   tile.seconds);
    } else {
      spdlog::error("map planes: tile {} (rank {}) failed: {}", tile.file, world.rank(),
                    tile.error);
    }
    mine.push_back(tile.ToJson());
  }
  const std::vector<std::uint8_t> bytes = nlohmann::json::to_cbor(mine);
  const std::vector<std::string> gathered =
      world.GatherToRoot(std::string(bytes.begin(), bytes.end()));
  if (!world.root()) return 0;
  return MergeAndWrite(args, options, index, CollectTiles(index, gathered), gt, eval_options);
}

}  // namespace

int RunTiledPlanes(const TiledPlanesArgs& args, const MapPlanesOptions& options) {
  const MpiWorld world;
  if (world.size() == 1) return RunTiledPlanesOnRanks(args, options, world);
  try {
    return RunTiledPlanesOnRanks(args, options, world);
  } catch (const InputError& e) {
    spdlog::error("rank {}: {}", world.rank(), e.what());
    world.Abort(2);  // the other ranks may be waiting for this one
  } catch (const std::exception& e) {
    spdlog::error("rank {}: internal error: {}", world.rank(), e.what());
    world.Abort(1);
  }
}

}  // namespace planeloc::cli
