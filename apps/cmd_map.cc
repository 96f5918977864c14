// `planeloc map build` (LiDAR scans + poses -> point-cloud map) and `planeloc map planes`
// (map -> tensor voting -> planes.json). The algorithms live in src/planeloc/map; this file wires
// files and flags (see docs/map.md).
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "command_registry.h"
#include "flags.h"
#include "map_tiles_cli.h"
#include "plane_map_eval_log.h"
#include "planeloc/io/kitti_sequence.h"
#include "planeloc/io/map_updates.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/io/point_cloud.h"
#include "planeloc/io/trajectory.h"
#include "planeloc/map/map_builder.h"
#include "planeloc/map/map_options.h"
#include "planeloc/map/map_planes.h"
#include "planeloc/map/map_update.h"
#include "planeloc/map/plane_map_eval.h"
#include "planeloc/map/pose_refinement.h"
#include "planeloc/util/safe_file.h"

namespace planeloc::cli {
namespace {

struct BuildArgs {
  std::string sequence;
  std::string poses;
  std::string out;
  std::string tiles_out;  // issue 15: tiles instead of one map file
  TilingOptions tiling;
  MapBuildOptions options;
};

struct RefineArgs {
  std::string sequence;
  std::string poses;
  std::string out;
  std::vector<double> prior_sigma;  // metres, degrees
  MapBuildOptions build;
  PoseRefinementOptions options;
};

struct PlanesArgs {
  std::string map;
  std::string tiles;  // issue 15: a tiles folder instead of --map
  std::string out;
  std::string ply;
  std::string options_yaml;
  std::string gt;
  double sigma = TensorVotingOptions().sigma;
  double voxel = MapPlanesOptions().voxel_size;
  std::string frame = "map";
  std::vector<double> up;
  double gt_min_area = PlaneMapEvalOptions().min_visible_area;
  bool gt_all_kinds = false;
};

// --every, --min-range, --max-range of the commands that read a sequence's scans.
void CheckScanFlags(const MapBuildOptions& o) {
  CheckFlag(o.every >= 1, "--every", o.every, "an integer >= 1 (1 = every scan)", "e.g. --every 5");
  CheckFlag(AtLeast(o.min_range, 0.0), "--min-range", o.min_range, "a distance in metres, >= 0",
            "e.g. --min-range 2");
  CheckFlag(AtLeast(o.max_range, 0.0) && o.max_range > o.min_range, "--max-range", o.max_range,
            fmt::format("a distance in metres above --min-range ({})", o.min_range),
            "e.g. --max-range 60");
}

// --sequence with its --poses (one per frame), after checking that --out can be written.
std::pair<KittiSequence, Trajectory> OpenSequenceWithPoses(const std::string& sequence_dir,
                                                           const std::string& poses_path,
                                                           const std::string& out) {
  CheckOutputPaths({{"--out", out}}, {{"--poses", poses_path}});
  KittiSequence sequence = KittiSequence::Open(sequence_dir);
  Trajectory poses = ReadKittiTrajectory(poses_path);
  CheckInput(poses.size() == sequence.size(), poses_path, 0,
             fmt::format("{} poses for the {} frames of {}", poses.size(), sequence.size(),
                         sequence.folder().string()),
             "give --poses the pose file of this sequence (one world_from_cam per frame)");
  return {std::move(sequence), std::move(poses)};
}

// --every, --min-range, --max-range on a command that reads a sequence's scans.
void AddScanOptions(CLI::App* command, MapBuildOptions& options) {
  command->add_option("--every", options.every, "Use every N-th scan")->capture_default_str();
  command->add_option("--min-range", options.min_range, "Drop closer points, metres")
      ->capture_default_str();
  command->add_option("--max-range", options.max_range, "Drop farther points, metres")
      ->capture_default_str();
}

int RunBuild(const BuildArgs& args) {
  const MapBuildOptions& o = args.options;
  CheckFlag(AtLeast(o.voxel_size, 0.0), "--voxel", o.voxel_size,
            "a voxel size in metres, >= 0 (0 = keep every point)", "e.g. --voxel 0.1");
  CheckScanFlags(o);
  CheckFlag(args.out.empty() != args.tiles_out.empty(), "--out/--tiles-out",
            args.out.empty() ? "(neither)" : "(both)", "a map file or a tiles folder, not both",
            "e.g. --out map.pcd, or --tiles-out tiles/ --tile-size 100 --overlap 5");
  if (!args.tiles_out.empty()) {
    TileArgs tile;
    tile.sequence = args.sequence;
    tile.poses = args.poses;
    tile.out = args.tiles_out;
    tile.tiling = args.tiling;
    tile.build = args.options;
    return RunTile(tile);
  }
  const auto [sequence, poses] = OpenSequenceWithPoses(args.sequence, args.poses, args.out);
  const PointCloud map = BuildMap(args.options, sequence, poses);
  WritePointCloud(args.out, map);
  spdlog::info("map build: wrote {} ({} points)", args.out, map.size());
  return 0;
}

int RunRefine(RefineArgs args) {
  if (!args.prior_sigma.empty()) {
    const bool ok = args.prior_sigma.size() == 2 && AtLeast(args.prior_sigma[0], 1e-6) &&
                    AtLeast(args.prior_sigma[1], 1e-6);
    CheckFlag(ok, "--prior-sigma", fmt::format("{}", fmt::join(args.prior_sigma, " ")),
              "two numbers > 0: the given poses' noise per axis in metres and degrees",
              "e.g. --prior-sigma 0.05 0.2");
    args.options.prior_sigma_translation = args.prior_sigma[0];
    args.options.prior_sigma_rotation_deg = args.prior_sigma[1];
  }
  CheckScanFlags(args.build);
  CheckFlag(AtLeast(args.options.voxel_size, 0.01), "--icp-voxel", args.options.voxel_size,
            "a voxel size in metres, >= 0.01", "e.g. --icp-voxel 0.2");
  const auto [sequence, poses] = OpenSequenceWithPoses(args.sequence, args.poses, args.out);
  const PoseRefinementResult result = RefinePoses(args.build, args.options, sequence, poses);
  WriteKittiTrajectory(args.out, result.poses);
  spdlog::info(
      "map refine-poses: {} scans, {} registrations ({} rejected); poses moved by {:.3f} m mean, "
      "{:.3f} m max, {:.3f} deg mean; wrote {}",
      result.scans, result.edges, result.rejected_edges, result.mean_correction,
      result.max_correction, result.mean_correction_deg, args.out);
  return 0;
}

MapPlanesOptions PlanesOptions(const PlanesArgs& args, bool sigma_given, bool voxel_given) {
  if (sigma_given) {
    CheckFlag(std::isfinite(args.sigma) && args.sigma > 0.0, "--sigma", args.sigma,
              "the tensor-voting scale in metres, > 0 (LiDAR maps: 0.2 to 2)", "e.g. --sigma 0.5");
  }
  if (voxel_given) {
    CheckFlag(AtLeast(args.voxel, 0.0) || args.voxel == -1.0, "--voxel", args.voxel,
              "a voxel size in metres >= 0 (0 = off), or -1 (sigma / 5)", "e.g. --voxel 0.1");
  }
  if (!args.up.empty()) {
    const bool finite = args.up.size() == 3 && std::isfinite(args.up[0]) &&
                        std::isfinite(args.up[1]) && std::isfinite(args.up[2]);
    CheckFlag(finite && std::abs(args.up[0]) + std::abs(args.up[1]) + std::abs(args.up[2]) > 0,
              "--up", fmt::format("{}", fmt::join(args.up, " ")),
              "three finite numbers, not all zero (a direction)", "e.g. --up 0 0 1");
  }
  MapPlanesOptions options;
  // Without --up (or `up` in the options file) the up axis is detected from the map.
  options.plane_extraction.detect_up = true;
  if (!args.options_yaml.empty()) LoadMapPlanesOptions(args.options_yaml, options);
  if (sigma_given) options.tensor_voting.sigma = args.sigma;  // the flags win over the file
  if (voxel_given) options.voxel_size = args.voxel;
  if (args.up.size() == 3) {
    options.plane_extraction.up = {args.up[0], args.up[1], args.up[2]};
    options.plane_extraction.detect_up = false;
  }
  options.Check();
  return options;
}

int RunPlanes(const PlanesArgs& args, bool sigma_given, bool voxel_given) {
  CheckFlag(args.map.empty() != args.tiles.empty(), "--map/--tiles",
            args.map.empty() ? "(neither)" : "(both)", "a map file or a tiles folder, not both",
            "e.g. --map map.pcd, or --tiles tiles/ (written by `planeloc map tile`)");
  CheckFlag(args.tiles.empty() || args.ply.empty(), "--ply", args.ply,
            "no --ply with --tiles (the labelled points stay in the tiles)", "drop --ply");
  CheckFlag(args.gt_min_area > 0.0, "--gt-min-area", args.gt_min_area, "an area in m^2, > 0",
            "e.g. --gt-min-area 1 for a room, 20 (the default) for a street");
  const MapPlanesOptions options = PlanesOptions(args, sigma_given, voxel_given);
  if (!args.tiles.empty())
    return RunTiledPlanes(
        {args.tiles, args.out, args.gt, args.frame, args.gt_min_area, args.gt_all_kinds}, options);
  CheckOutputPaths({{"--out", args.out}, {"--ply", args.ply}},
                   {{"--map", args.map}, {"--gt", args.gt}, {"--options", args.options_yaml}});
  // Voxel-filtered while reading: memory follows the voxels, not the points of the file.
  PointCloudReadOptions read_options;
  read_options.voxel_size = options.EffectiveVoxelSize();
  const PointCloud map = ReadPointCloud(args.map, read_options);
  spdlog::info(
      "map planes: {} points in {}{}, {} after the {} m voxel filter", map.source_points, args.map,
      map.dropped_invalid > 0
          ? fmt::format(" ({} NaN points of the organized cloud dropped)", map.dropped_invalid)
          : "",
      map.size(), read_options.voxel_size);
  MapPlanesOutput output = RunMapPlanes(map, options);
  PlaneMap& planes = output.extraction.plane_map;
  const Eigen::Vector3d& up = output.extraction.up;
  spdlog::info("map planes: frame '{}' (the map's), up = [{:.3f}, {:.3f}, {:.3f}] {}", args.frame,
               up.x(), up.y(), up.z(),
               output.extraction.up_detected
                   ? "detected from the dominant horizontal plane (give --up to override)"
               : options.plane_extraction.detect_up ? "(default: no plane to detect it from)"
                                                    : "(given)");
  planes.frame.name = args.frame;
  planes.frame.map_file = std::filesystem::absolute(args.map).lexically_normal().string();
  planes.frame.up = up;
  planes.frame.up_source = output.extraction.up_detected ? "detected" : "given";
  spdlog::info("map planes: tensor voting {:.2f} s, plane extraction {:.2f} s, {} planes",
               output.voting_seconds, output.extraction_seconds, planes.planes.size());
  RequirePlanarStructure(planes, args.map, map.size(), options);
  if (!args.gt.empty()) {
    // Ground truth (the simulator's world/planes_gt.json): issue 4's acceptance numbers, logged
    // and stored in the stats of planes.json.
    PlaneMapEvalOptions eval_options;
    // One point a voxel face: `map build`'s default 0.10 m voxels, or the voxel filter's.
    eval_options.point_area =
        output.voxel_size > 0.0 ? output.voxel_size * output.voxel_size : 0.01;
    eval_options.min_visible_area = args.gt_min_area;
    if (args.gt_all_kinds) eval_options.kinds = {"ground", "facade", "other"};
    const PlaneMapEvaluation evaluation = EvaluatePlaneMap(
        output.points, output.extraction.point_plane, planes, ReadPlaneMap(args.gt), eval_options);
    LogPlaneMapEvaluation(args.gt, evaluation, eval_options);
    planes.stats["gt_evaluation"] = evaluation.ToJson();
  }
  WritePlaneMap(args.out, planes);
  if (!args.ply.empty()) {
    PointCloud labelled;
    labelled.points = output.points;
    labelled.colors = PlaneColors(output);
    WritePointCloud(args.ply, labelled);
  }
  return 0;
}

// A subcommand of `map` and what runs it when it was chosen.
struct MapSubcommand {
  CLI::App* command = nullptr;
  CommandRunner run;
};

MapSubcommand AddBuildCommand(CLI::App& map) {
  auto build_args = std::make_shared<BuildArgs>();
  auto* build = map.add_subcommand("build", "Accumulate a KITTI sequence's Velodyne scans");
  build->add_option("--sequence", build_args->sequence, "KITTI sequence folder (odometry or raw)")
      ->required();
  build->add_option("--poses", build_args->poses, "KITTI pose file (world_from_cam per frame)")
      ->required();
  build->add_option("--out", build_args->out, "Map file (.pcd, .ply or .xyz)");
  build->add_option("--tiles-out", build_args->tiles_out,
                    "Write tiles (and index.json) to this folder instead of one map, streaming "
                    "the scans (see `map tile`)");
  build->add_option("--tile-size", build_args->tiling.tile_size, "Tile side, metres (--tiles-out)")
      ->capture_default_str();
  build
      ->add_option("--overlap", build_args->tiling.overlap,
                   "Band of neighbour points stored with each tile, metres (--tiles-out)")
      ->capture_default_str();
  build->add_option("--voxel", build_args->options.voxel_size, "Voxel size, metres (0 = none)")
      ->capture_default_str();
  AddScanOptions(build, build_args->options);
  return {build, [build_args] { return RunBuild(*build_args); }};
}

MapSubcommand AddRefineCommand(CLI::App& map) {
  auto refine_args = std::make_shared<RefineArgs>();
  auto* refine = map.add_subcommand(
      "refine-poses",
      "Refine noisy map poses (GNSS/INS) by registering each scan to its predecessors (ICP) in a "
      "pose graph with the given poses as priors; writes KITTI poses for `map build`");
  refine->add_option("--sequence", refine_args->sequence, "KITTI sequence folder with velodyne/")
      ->required();
  refine->add_option("--poses", refine_args->poses, "KITTI pose file (world_from_cam per frame)")
      ->required();
  refine->add_option("--out", refine_args->out, "Refined KITTI pose file")->required();
  refine
      ->add_option("--prior-sigma", refine_args->prior_sigma,
                   "Noise of the given poses per axis: metres degrees (default 0.05 0.2)")
      ->expected(2);
  AddScanOptions(refine, refine_args->build);
  refine
      ->add_option("--icp-voxel", refine_args->options.voxel_size,
                   "Scans downsampled to this voxel for ICP, metres")
      ->capture_default_str();
  return {refine, [refine_args] { return RunRefine(*refine_args); }};
}

MapSubcommand AddPlanesCommand(CLI::App& map) {
  auto planes_args = std::make_shared<PlanesArgs>();
  auto* planes = map.add_subcommand("planes", "Tensor voting and plane extraction -> planes.json");
  planes->add_option("--map", planes_args->map, "Map (.pcd, .ply or .xyz)");
  planes->add_option("--tiles", planes_args->tiles,
                     "Tiles folder (`map tile`) instead of --map: tile by tile, or over MPI ranks "
                     "under mpirun/srun");
  planes->add_option("--out", planes_args->out, "Plane map JSON")->required();
  planes->add_option("--ply", planes_args->ply, "Also write the map coloured by plane and class");
  auto* sigma = planes->add_option("--sigma", planes_args->sigma,
                                   "Tensor-voting scale sigma, metres (overrides --options)");
  sigma->capture_default_str();
  planes->add_option("--options", planes_args->options_yaml, "YAML options (see docs/map.md)");
  planes
      ->add_option("--up", planes_args->up,
                   "Up direction of the map frame, e.g. 0 0 1 (Velodyne, LOAM, LIO-SAM) or 0 -1 0 "
                   "(KITTI camera world); default: detected from the dominant horizontal plane")
      ->expected(3);
  auto* voxel = planes->add_option(
      "--voxel", planes_args->voxel,
      "Voxel filter before tensor voting, metres (-1 = sigma / 5 = 0.1 m by default; 0 = off)");
  voxel->capture_default_str();
  planes
      ->add_option("--frame", planes_args->frame,
                   "Name of the map's frame, recorded in planes.json (`run` needs its initial "
                   "pose in this frame)")
      ->capture_default_str();
  planes->add_option("--gt", planes_args->gt,
                     "Ground-truth planes (a simulated world's world/planes_gt.json): log and "
                     "store the accuracy of the extracted planes");
  planes
      ->add_option("--gt-min-area", planes_args->gt_min_area,
                   "With --gt: check the GT planes showing at least this area in the map, m^2 "
                   "(1 for a room)")
      ->capture_default_str();
  planes->add_flag("--gt-all-kinds", planes_args->gt_all_kinds,
                   "With --gt: check ceilings and table tops (\"other\") too, not only ground "
                   "and facades");
  return {planes, [planes_args, sigma, voxel] {
            return RunPlanes(*planes_args, sigma->count() > 0, voxel->count() > 0);
          }};
}

MapSubcommand AddTileCommand(CLI::App& map) {
  auto tile_args = std::make_shared<TileArgs>();
  auto* tile = map.add_subcommand("tile", "Cut a map (or a sequence's scans) into tiles");
  tile->add_option("--map", tile_args->map, "Map (.pcd, .ply or .xyz)");
  tile->add_option("--sequence", tile_args->sequence, "KITTI sequence folder, instead of --map");
  tile->add_option("--poses", tile_args->poses, "KITTI pose file of --sequence");
  tile->add_option("--out", tile_args->out, "Tiles folder (created; tiles and index.json)")
      ->required();
  tile->add_option("--tile-size", tile_args->tiling.tile_size, "Tile side, metres")
      ->capture_default_str();
  tile->add_option("--overlap", tile_args->tiling.overlap,
                   "Band of neighbour points stored with each tile, metres")
      ->capture_default_str();
  tile->add_option("--voxel", tile_args->build.voxel_size, "--sequence: voxel size, metres")
      ->capture_default_str();
  tile->add_option("--every", tile_args->build.every, "--sequence: use every N-th scan")
      ->capture_default_str();
  tile->add_option("--min-range", tile_args->build.min_range, "--sequence: metres")
      ->capture_default_str();
  tile->add_option("--max-range", tile_args->build.max_range, "--sequence: metres")
      ->capture_default_str();
  return {tile, [tile_args] { return RunTile(*tile_args); }};
}

struct UpdateArgs {
  std::string planes;
  std::vector<std::string> updates;
  std::string out;
  std::string report;
};

int RunUpdate(const UpdateArgs& args) {
  std::vector<FlagPath> inputs = {{"--planes", args.planes}};
  for (const std::string& path : args.updates) inputs.push_back({"--updates", path});
  // The output never replaces an input (planes.json above all): a failed or wrong update must
  // leave the map it started from.
  CheckOutputPaths({{"--out", args.out}, {"--report", args.report}}, inputs);
  const PlaneMap map = ReadPlaneMap(args.planes);
  const std::string hash = FileHash(args.planes);
  std::vector<MapUpdates> updates;
  for (const std::string& path : args.updates) {
    updates.push_back(ReadMapUpdates(path));
    CheckUpdatesMatch(map, hash, updates.back());
  }
  const MapUpdateResult result = FuseMapUpdates(map, updates);
  WritePlaneMap(args.out, result.planes);
  std::map<std::string, int> counts;
  for (const PlaneChange& change : result.changes) ++counts[ToString(change.action)];
  spdlog::info("map update: {} planes, {} moved, {} retired, {} confirmed, {} unchanged -> {}",
               map.planes.size(), counts["moved"], counts["retired"], counts["confirmed"],
               counts["unchanged"], args.out);
  if (!args.report.empty()) {
    WriteFileWhole(args.report, ChangesMarkdown(map, updates, result));
    spdlog::info("changes: {}", args.report);
  }
  return 0;
}

MapSubcommand AddUpdateCommand(CLI::App& map) {
  auto update_args = std::make_shared<UpdateArgs>();
  auto* update = map.add_subcommand(
      "update",
      "Fuse what runs learned about a plane map (`run --map-update` files) into a new plane map: "
      "moves, confirms or retires planes (docs/map-update.md)");
  update->add_option("--planes", update_args->planes, "The plane map the runs used")->required();
  update->add_option("--updates", update_args->updates, "One or more `run --map-update` files")
      ->required()
      ->expected(1, -1);
  update->add_option("--out", update_args->out, "The updated plane map (never the input)")
      ->required();
  update->add_option("--report", update_args->report, "What changed and why, as Markdown");
  return {update, [update_args] { return RunUpdate(*update_args); }};
}

CommandRunner SetupMap(CLI::App& app) {
  auto* map = app.add_subcommand("map", "LiDAR map: build it from scans, extract its planes");
  map->require_subcommand(1);
  const MapSubcommand build = AddBuildCommand(*map);
  const MapSubcommand refine = AddRefineCommand(*map);
  const MapSubcommand planes = AddPlanesCommand(*map);
  const MapSubcommand tile = AddTileCommand(*map);
  const MapSubcommand update = AddUpdateCommand(*map);
  return [build, refine, tile, planes, update]() {
    for (const MapSubcommand* chosen : {&build, &refine, &tile, &planes, &update}) {
      if (chosen->command->parsed()) return chosen->run();
    }
    return 2;
  };
}

const CommandRegistrar kRegistrar("map", SetupMap);

}  // namespace
}  // namespace planeloc::cli
